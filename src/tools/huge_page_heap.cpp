// SPDX-License-Identifier: GPL-3.0-or-later
// A restart with glibc's malloc on transparent huge pages (huge_page_heap.h).
#include "huge_page_heap.h"

#include <cstdlib> // and with glibc, <features.h>: __GLIBC__

// __GLIBC_PREREQ exists only with glibc, so the test is nested.
#if defined(__linux__) && defined(__GLIBC__)
#if __GLIBC_PREREQ(2, 35)
#define PCL_MS_HUGE_PAGE_HEAP 1
#endif
#endif

#if defined(PCL_MS_HUGE_PAGE_HEAP)
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <string>

namespace pcl_ms_tools {
namespace {

constexpr const char *kChoice = "PCL_MS_HUGE_PAGES";
constexpr const char *kTunable = "glibc.malloc.hugetlb";

/// Whether the kernel gives huge pages only where advised: under "always"
/// malloc's blocks get them anyway, under "never" advice is ignored.
bool hugePagesOnAdvice() {
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  return std::getline(mode, line) && line.find("[madvise]") != std::string::npos;
}

bool contains(const char *text, const char *part) {
  return text != nullptr && std::strstr(text, part) != nullptr;
}

/// PCL_MS_HUGE_PAGES: "0" no, "1" yes, unset (or anything else) `when`'s
/// default.
bool wanted(HugePageHeap when) {
  const char *choice = std::getenv(kChoice);
  if (choice != nullptr && std::strcmp(choice, "0") == 0)
    return false;
  if (choice != nullptr && std::strcmp(choice, "1") == 0)
    return true;
  return when == HugePageHeap::kByDefault;
}

} // namespace

void restartWithHugePageHeap(char **argv, HugePageHeap when) {
  if (!wanted(when) || contains(std::getenv("GLIBC_TUNABLES"), kTunable) ||
      contains(std::getenv("LD_PRELOAD"), "vgpreload") || !hugePagesOnAdvice())
    return;
  const char *given = std::getenv("GLIBC_TUNABLES");
  std::string tunables = std::string(kTunable) + "=1";
  if (given != nullptr && *given != '\0')
    tunables = std::string(given) + ":" + tunables;
  if (setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0 || setenv(kChoice, "1", 1) != 0)
    return;
  execv("/proc/self/exe", argv);
  // Still here: the restart failed; go on as started, 4 kB pages.
}

} // namespace pcl_ms_tools

#else

namespace pcl_ms_tools {

void restartWithHugePageHeap(char **, HugePageHeap) {}

} // namespace pcl_ms_tools

#endif
