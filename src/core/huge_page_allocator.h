// SPDX-License-Identifier: GPL-3.0-or-later
// The allocator of CGAL's triangulation containers in the core: their large
// blocks on transparent huge pages (docs/algorithm.md, "Code layout",
// "Memory pages"). Internal to the library: not installed.
//
// Include this before any other CGAL header: CGAL's Compact_container, which
// stores a triangulation's cells and vertices, takes its allocator from the
// CGAL_ALLOCATOR macro where it is first read, so this header reads it with
// the macro set to HugePageAllocator and restores CGAL's default for every
// other container.
#pragma once

#ifdef CGAL_COMPACT_CONTAINER_H
#error "huge_page_allocator.h must come before CGAL's Compact_container.h"
#endif

#include <CGAL/memory.h>

#include <cstddef>
#include <memory>
#include <new>

namespace pcl_ms {
namespace detail {

#if defined(__linux__) && !defined(__SANITIZE_ADDRESS__)
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PCL_MS_HUGE_PAGE_REGIONS 0
#endif
#endif
#ifndef PCL_MS_HUGE_PAGE_REGIONS
#define PCL_MS_HUGE_PAGE_REGIONS 1
#endif
#else
// AddressSanitizer checks the heap's blocks, which regions would hide.
#define PCL_MS_HUGE_PAGE_REGIONS 0
#endif

/// Blocks from this size on come from huge-page regions; smaller ones (a
/// small cloud's whole triangulation) from the ordinary heap.
inline constexpr std::size_t huge_page_block_bytes = std::size_t(64) << 10;

/// A block of `bytes` (at least huge_page_block_bytes), 64-byte aligned,
/// from the calling thread's current region; throws std::bad_alloc.
void *allocateFromRegion(std::size_t bytes);
/// Gives back a block of allocateFromRegion, from any thread. A region is
/// unmapped when its last block goes and no thread allocates from it.
void deallocateToRegion(void *block) noexcept;
/// Regions mapped now, in all threads (for tests).
std::size_t regionsMapped() noexcept;

/// std::allocator's interface; blocks of huge_page_block_bytes or more come
/// from regions of 2 MB-aligned memory, advised onto huge pages where they
/// pay (hugePagesPay()), bump allocated, each unmapped when all its blocks
/// are freed.
/// That suits CGAL's Compact_container, which frees all its blocks together:
/// a triangulation's cells, visited through neighbour pointers all over the
/// store, then lie on 512 times fewer pages.
template <typename T> struct HugePageAllocator {
  using value_type = T;

  HugePageAllocator() noexcept = default;
  template <typename U> HugePageAllocator(const HugePageAllocator<U> &) noexcept {}

  T *allocate(std::size_t count) {
    if (!fromRegion(count))
      return std::allocator<T>().allocate(count);
    if (count > static_cast<std::size_t>(-1) / sizeof(T))
      throw std::bad_array_new_length();
    return static_cast<T *>(allocateFromRegion(count * sizeof(T)));
  }
  void deallocate(T *block, std::size_t count) noexcept {
    if (fromRegion(count))
      deallocateToRegion(block);
    else
      std::allocator<T>().deallocate(block, count);
  }

  friend bool operator==(const HugePageAllocator &, const HugePageAllocator &) { return true; }
  friend bool operator!=(const HugePageAllocator &, const HugePageAllocator &) { return false; }

private:
  static bool fromRegion(std::size_t count) {
    return PCL_MS_HUGE_PAGE_REGIONS && alignof(T) <= 64 &&
           count >= huge_page_block_bytes / sizeof(T);
  }
};

} // namespace detail
} // namespace pcl_ms

#pragma push_macro("CGAL_ALLOCATOR")
#undef CGAL_ALLOCATOR
#define CGAL_ALLOCATOR(T) ::pcl_ms::detail::HugePageAllocator<T>
#include <CGAL/Compact_container.h>
#pragma pop_macro("CGAL_ALLOCATOR")
