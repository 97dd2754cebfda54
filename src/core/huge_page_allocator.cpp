// SPDX-License-Identifier: GPL-3.0-or-later
// Huge-page regions for the large blocks of CGAL's triangulation containers
// (huge_page_allocator.h; docs/algorithm.md, "Memory pages").
#include "huge_page_allocator.h"
#include "populate_pages.h"

#include <atomic>
#include <cstdint>

#if PCL_MS_HUGE_PAGE_REGIONS
#include <sys/mman.h>
#endif

namespace pcl_ms {
namespace detail {
namespace {

std::atomic<std::size_t> regions_mapped{0};

#if PCL_MS_HUGE_PAGE_REGIONS

// A region's size: sixteen huge pages. A 2,000-point cloud's triangulation
// (all its blocks below huge_page_block_bytes) maps none, 300,000 points'
// cells (about 150 MB) fill five.
constexpr std::size_t region_bytes = 16 * huge_page_bytes;
// Each block starts with the address of its region, padded to keep the
// block's 64-byte alignment.
constexpr std::size_t block_header = 64;

/// Sits at the start of its region. `references` counts the live blocks,
/// plus one while the region is its thread's current one; `used` is moved
/// only by that thread.
struct Region {
  std::atomic<std::size_t> references;
  std::size_t size;
  std::size_t used;
};

std::size_t roundUp(std::size_t value, std::size_t step) {
  return (value + step - 1) / step * step;
}

/// `bytes` (a multiple of huge_page_bytes) aligned to a huge page, advised onto
/// huge pages or off them (hugePagesPay()), with one reference.
Region *mapRegion(std::size_t bytes) {
  void *mapped = mmap(nullptr, bytes + huge_page_bytes, PROT_READ | PROT_WRITE,
                      MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (mapped == MAP_FAILED)
    throw std::bad_alloc();
  // mmap aligns to 4 kB only: the slack before and after the aligned range
  // goes back at once.
  const auto start = reinterpret_cast<std::uintptr_t>(mapped);
  const std::uintptr_t aligned = roundUp(start, huge_page_bytes);
  if (aligned > start)
    munmap(mapped, aligned - start);
  if (aligned + bytes < start + bytes + huge_page_bytes)
    munmap(reinterpret_cast<void *>(aligned + bytes), start + huge_page_bytes - aligned);
  void *region_start = reinterpret_cast<void *>(aligned);
  // A hint: where the kernel has transparent huge pages off, the region is
  // ordinary memory. Where they do not pay, the region asks for 4 kB pages,
  // also from a kernel that would make huge pages unasked.
  madvise(region_start, bytes, hugePagesPay() ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
  regions_mapped.fetch_add(1, std::memory_order_relaxed);
  return new (region_start) Region{{1}, bytes, block_header};
}

void dropReference(Region *region) noexcept {
  if (region->references.fetch_sub(1, std::memory_order_acq_rel) != 1)
    return;
  const std::size_t size = region->size;
  region->~Region();
  munmap(region, size);
  regions_mapped.fetch_sub(1, std::memory_order_relaxed);
}

/// The region the thread allocates from; its reference goes when the
/// thread ends.
struct CurrentRegion {
  Region *region = nullptr;
  ~CurrentRegion() {
    if (region)
      dropReference(region);
  }
};
thread_local CurrentRegion current;

void *placeBlock(Region *region, std::size_t bytes) {
  char *block = reinterpret_cast<char *>(region) + region->used;
  region->used += bytes;
  *reinterpret_cast<Region **>(block) = region;
  return block + block_header;
}

#endif

} // namespace

#if PCL_MS_HUGE_PAGE_REGIONS

void *allocateFromRegion(std::size_t bytes) {
  // More than the address space holds; rounding it up below would wrap.
  if (bytes > std::size_t(-1) / 4)
    throw std::bad_alloc();
  const std::size_t needed = roundUp(bytes, 64) + block_header;
  if (needed > region_bytes - block_header) {
    // A block larger than a region gets one of its own, unshared.
    Region *own = mapRegion(roundUp(needed + block_header, huge_page_bytes));
    return placeBlock(own, needed);
  }
  Region *region = current.region;
  if (!region || region->size - region->used < needed) {
    current.region = nullptr;
    if (region)
      dropReference(region);
    region = mapRegion(region_bytes);
    current.region = region;
  }
  region->references.fetch_add(1, std::memory_order_relaxed);
  return placeBlock(region, needed);
}

void deallocateToRegion(void *block) noexcept {
  char *base = static_cast<char *>(block) - block_header;
  Region *region = *reinterpret_cast<Region **>(base);
  // The thread's last block in its current region: the region goes with it,
  // so that a finished triangulation leaves no memory behind (a reference
  // alone would keep its touched pages until the thread allocates again).
  if (region == current.region && region->references.load(std::memory_order_acquire) == 2) {
    current.region = nullptr;
    dropReference(region);
  }
  dropReference(region);
}

#else

void *allocateFromRegion(std::size_t bytes) { return ::operator new(bytes); }

void deallocateToRegion(void *block) noexcept { ::operator delete(block); }

#endif

std::size_t regionsMapped() noexcept { return regions_mapped.load(std::memory_order_relaxed); }

} // namespace detail
} // namespace pcl_ms
