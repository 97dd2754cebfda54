// SPDX-License-Identifier: GPL-3.0-or-later
//
// The command-line programs' heap on transparent huge pages
// (docs/algorithm.md, "Memory pages").
#pragma once

namespace pcl_ms_tools {

/// When a program starts again on the huge-page heap.
enum class HugePageHeap {
  /// Unless PCL_MS_HUGE_PAGES=0: the MPI tool, whose exchanges fill fresh
  /// buffers of hundreds of megabytes.
  kByDefault,
  /// Only with PCL_MS_HUGE_PAGES=1: pcl_ms_reconstruct. Where fresh huge
  /// pages are slow to fault in (a virtual machine whose host backs them
  /// on first touch), the heap on huge pages made its one-piece runs slower
  /// and its bucketed runs no faster, and the restart costs a program start
  /// (bench/README.md, "The one-process tool's heap").
  kOnRequest,
};

/// Starts this program again, once, in place (same process id, arguments
/// and environment), with glibc's malloc advising the blocks it maps onto
/// transparent huge pages (GLIBC_TUNABLES=glibc.malloc.hugetlb=1, read only
/// when a program starts), if `when` and PCL_MS_HUGE_PAGES ask for it.
/// Returns without doing anything where that would change nothing: not
/// glibc 2.35 or later on Linux, the kernel's huge pages not "madvise", the
/// tunable already given (as after the restart, which also sets
/// PCL_MS_HUGE_PAGES to 1), or under Valgrind (which would not follow).
/// Also returns if the restart fails. Call first thing in main, before any
/// thread or MPI starts.
void restartWithHugePageHeap(char **argv, HugePageHeap when);

} // namespace pcl_ms_tools
