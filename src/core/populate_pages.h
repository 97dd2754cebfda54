// SPDX-License-Identifier: GPL-3.0-or-later
// Fresh pages faulted in, in one call, before a large array is written in
// full (docs/algorithm.md, "Memory pages"). Internal: not installed.
#pragma once

#include <cstddef>
#include <vector>

namespace pcl_ms {
namespace detail {

/// Below this many bytes nothing is asked of the kernel: a small array's
/// pages are few, and often reused heap pages already.
inline constexpr std::size_t min_populated_bytes = std::size_t(16) << 10;

/// A transparent huge page where base pages are 4 kB (x86-64, most arm64
/// kernels). Both the populated arrays and the triangulation's store
/// (huge_page_allocator.h) work in whole pages of this size.
inline constexpr std::size_t huge_page_bytes = std::size_t(2) << 20;

/// Whether transparent huge pages pay here: where a first write to a fresh
/// 4 kB page is slow. A probe of a few pages decides, once per process,
/// when the first region is mapped or the first array of 2 MB or more is
/// populated, so a small cloud never pays for it. Where page faults are
/// cheap the kernel's zeroing of a whole huge page at once costs more than
/// the 511 faults it saves, and neither the triangulation's store nor the
/// populated arrays ask for huge pages. Always false outside Linux.
bool hugePagesPay();

/// The answer hugePagesPay() gives, or that the probe has not run yet.
enum class HugePagesChoice { undecided, pay, do_not_pay };
/// For tests: the choice so far (never undecided outside Linux).
HugePagesChoice hugePagesChoice();
/// For tests: the choice from now on; `undecided` has the probe run again.
void setHugePagesChoice(HugePagesChoice choice);

/// Has the kernel fault in, writable, every whole page of [data, data +
/// bytes) in one call (Linux 5.14's MADV_POPULATE_WRITE) instead of one
/// fault per page at the first write. Where hugePagesPay(), the whole huge
/// pages inside the range are advised onto transparent huge pages first.
/// Only for memory the caller is about to write in full. The contents stay
/// as they were. Nothing happens on other systems, on older kernels or when
/// it fails: it only changes how fast the first writes go.
void populateForWriting(const void *data, std::size_t bytes) noexcept;

/// populateForWriting() of a vector's whole capacity.
template <typename T, typename Allocator>
void populateCapacity(const std::vector<T, Allocator> &values) noexcept {
  populateForWriting(values.data(), values.capacity() * sizeof(T));
}

/// values.resize(size) on pages faulted in beforehand, for a vector whose
/// every element the caller is about to write.
template <typename T, typename Allocator>
void resizeForWriting(std::vector<T, Allocator> &values, std::size_t size) {
  values.reserve(size);
  populateCapacity(values);
  values.resize(size);
}

/// A copy of `values` of exactly their size, on pages faulted in
/// beforehand: to keep what was gathered in a list with room to spare.
template <typename T> std::vector<T> exactCopy(const std::vector<T> &values) {
  std::vector<T> copy;
  copy.reserve(values.size());
  populateCapacity(copy);
  copy.assign(values.begin(), values.end());
  return copy;
}

} // namespace detail
} // namespace pcl_ms
