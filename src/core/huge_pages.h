// SPDX-License-Identifier: GPL-3.0-or-later
// The core's large arrays on transparent huge pages (docs/algorithm.md,
// "Code layout", "Memory pages"). Internal to the library: not installed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace pcl_ms {
namespace detail {

/// Asks the kernel to back the whole 2 MB pages inside [data, data + bytes)
/// with transparent huge pages when they are first touched. A hint: where
/// the system has them off, or the range holds no whole huge page, nothing
/// changes.
inline void adviseHugePages(const void *data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t huge_page = std::uintptr_t(1) << 21;
  const auto start = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t begin = (start + huge_page - 1) & ~(huge_page - 1);
  const std::uintptr_t end = (start + bytes) & ~(huge_page - 1);
  if (data != nullptr && end > begin)
    madvise(reinterpret_cast<void *>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

/// v.reserve(count), with new room advised onto huge pages before anything
/// touches it.
template <typename T> void reserveOnHugePages(std::vector<T> &v, std::size_t count) {
  if (count <= v.capacity())
    return;
  v.reserve(count);
  adviseHugePages(v.data(), v.capacity() * sizeof(T));
}

/// v.assign(count, value), on huge pages where v needs new room.
template <typename T>
void assignOnHugePages(std::vector<T> &v, std::size_t count, const T &value = T()) {
  if (count > v.capacity()) {
    std::vector<T>().swap(v);
    reserveOnHugePages(v, count);
  }
  v.assign(count, value);
}

} // namespace detail
} // namespace pcl_ms
