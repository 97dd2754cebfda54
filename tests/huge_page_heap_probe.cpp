// SPDX-License-Identifier: GPL-3.0-or-later
// Restarts as the reconstruct tools do (restartWithHugePageHeap), then
// prints what it runs with, for tests/test_huge_page_heap.cpp: a line
// "started <pid>" each time main begins, then the tunables, the choice
// variable, the process id and the arguments.
#include "huge_page_heap.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

int main(int, char **argv) {
  std::printf("started %ld\n", static_cast<long>(getpid()));
  std::fflush(stdout); // a restart replaces the buffer
  // As pcl_ms_reconstruct does with PROBE_ON_REQUEST set, else as the MPI
  // tool does.
  pcl_ms_tools::restartWithHugePageHeap(argv, std::getenv("PROBE_ON_REQUEST") != nullptr
                                                  ? pcl_ms_tools::HugePageHeap::kOnRequest
                                                  : pcl_ms_tools::HugePageHeap::kByDefault);
  const char *tunables = std::getenv("GLIBC_TUNABLES");
  const char *choice = std::getenv("PCL_MS_HUGE_PAGES");
  std::printf("tunables [%s]\nchoice [%s]\npid %ld\n", tunables ? tunables : "",
              choice ? choice : "", static_cast<long>(getpid()));
  for (char **argument = argv + 1; *argument != nullptr; ++argument)
    std::printf("argument [%s]\n", *argument);
  return 0;
}
