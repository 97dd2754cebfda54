// SPDX-License-Identifier: GPL-3.0-or-later
// Pages faulted in ahead of a full write (populate_pages.h).
#include "populate_pages.h"

#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace pcl_ms {
namespace detail {

#if defined(__linux__)

namespace {
// Linux's value, which older headers lack.
constexpr int populate_write_advice = 23;

/// The whole pages of size `page` inside [start, start + bytes), advised.
void advise(std::uintptr_t start, std::size_t bytes, std::uintptr_t page, int advice) noexcept {
  const std::uintptr_t first = (start + page - 1) & ~(page - 1);
  const std::uintptr_t last = (start + bytes) & ~(page - 1);
  if (last > first)
    madvise(reinterpret_cast<void *>(first), last - first, advice);
}
} // namespace

void populateForWriting(const void *data, std::size_t bytes) noexcept {
  if (bytes < min_populated_bytes)
    return;
  static const std::uintptr_t page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
  const auto start = reinterpret_cast<std::uintptr_t>(data);
  // The whole huge pages inside go on huge pages, like the triangulation's
  // store (huge_page_allocator.h): one fault each instead of 512.
  advise(start, bytes, huge_page_bytes, MADV_HUGEPAGE);
  advise(start, bytes, page, populate_write_advice);
}

#else

void populateForWriting(const void *, std::size_t) noexcept {}

#endif

} // namespace detail
} // namespace pcl_ms
