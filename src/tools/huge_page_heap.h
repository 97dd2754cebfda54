// SPDX-License-Identifier: GPL-3.0-or-later
//
// The command-line programs' heap on transparent huge pages
// (docs/algorithm.md, "Memory pages").
#pragma once

namespace pcl_ms_tools {

/// Starts this program again, once, in place (same process id, arguments
/// and environment), with glibc's malloc advising the blocks it maps onto
/// transparent huge pages (GLIBC_TUNABLES=glibc.malloc.hugetlb=1, read only
/// when a program starts). Returns without doing anything where that would
/// change nothing or is not wanted: not glibc 2.35 or later on Linux, the
/// kernel's huge pages not "madvise", the tunable already given, under
/// Valgrind (which would not follow), or PCL_MS_HUGE_PAGES set (to 0 to
/// keep 4 kB pages; the restart sets it to 1). Also returns if the restart
/// fails. Call first thing in main, before any thread or MPI starts.
void restartWithHugePageHeap(char **argv);

} // namespace pcl_ms_tools
