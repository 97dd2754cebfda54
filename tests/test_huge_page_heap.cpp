// SPDX-License-Identifier: GPL-3.0-or-later
// The reconstruct tools' restart onto a huge-page heap (huge_page_heap.h),
// through a probe program that restarts the same way: by default (the MPI
// tool) or on request (pcl_ms_reconstruct).
#include "program_test.h"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <string>

namespace {

using pcl_ms_test::contains;
using pcl_ms_test::quoted;

class HugePageHeap : public pcl_ms_test::TempDirTest {
protected:
  /// Runs the probe with a clean choice and `environment` (NAME=value ...).
  void runProbe(const std::string &environment) {
    const std::string probe = std::string(PCL_MS_BINARY_DIR) + "/huge_page_heap_probe";
    ASSERT_EQ(runProgram("env", "-u PCL_MS_HUGE_PAGES -u GLIBC_TUNABLES -u LD_PRELOAD " +
                                    environment + " " + quoted(probe) + " 'a b' -c"),
              0)
        << stderr_;
    const std::regex started("started ([0-9]+)\n");
    starts_ = 0;
    for (auto it = std::sregex_iterator(stdout_.begin(), stdout_.end(), started);
         it != std::sregex_iterator(); ++it) {
      ++starts_;
      EXPECT_TRUE(contains(stdout_, "pid " + (*it)[1].str() + "\n")) << stdout_;
    }
    EXPECT_TRUE(contains(stdout_, "argument [a b]\nargument [-c]\n")) << stdout_;
  }
  int starts_ = 0;
};

/// Whether this kernel gives transparent huge pages only where advised,
/// under a glibc that has the tunable: where the tools restart.
bool hugePagesOnAdvice() {
#if defined(__GLIBC__) && defined(__linux__)
  if (!__GLIBC_PREREQ(2, 35))
    return false;
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  return std::getline(mode, line) && contains(line, "[madvise]");
#else
  return false;
#endif
}

TEST_F(HugePageHeap, RestartsOnceInPlaceWithTheTunableAndTheSameArguments) {
  runProbe("");
  if (!hugePagesOnAdvice()) {
    EXPECT_EQ(starts_, 1);
    EXPECT_TRUE(contains(stdout_, "tunables []\n")) << stdout_;
    return;
  }
  EXPECT_EQ(starts_, 2); // the same process id both times (checked in runProbe)
  EXPECT_TRUE(contains(stdout_, "tunables [glibc.malloc.hugetlb=1]\nchoice [1]\n")) << stdout_;
}

TEST_F(HugePageHeap, KeepsTheUsersTunables) {
  runProbe("GLIBC_TUNABLES=glibc.malloc.arena_max=2");
  if (!hugePagesOnAdvice())
    GTEST_SKIP() << "transparent huge pages are not on advice here";
  EXPECT_EQ(starts_, 2);
  EXPECT_TRUE(contains(stdout_, "tunables [glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1]\n"))
      << stdout_;
}

TEST_F(HugePageHeap, OnRequestRestartsOnlyWhenAskedTo) {
  runProbe("PROBE_ON_REQUEST=1");
  EXPECT_EQ(starts_, 1);
  EXPECT_TRUE(contains(stdout_, "tunables []\nchoice []\n")) << stdout_;
  runProbe("PROBE_ON_REQUEST=1 PCL_MS_HUGE_PAGES=1");
  if (!hugePagesOnAdvice())
    GTEST_SKIP() << "transparent huge pages are not on advice here";
  EXPECT_EQ(starts_, 2);
  EXPECT_TRUE(contains(stdout_, "tunables [glibc.malloc.hugetlb=1]\nchoice [1]\n")) << stdout_;
}

TEST_F(HugePageHeap, StaysAsStartedWhenTheUserChoseOrUnderValgrind) {
  for (const std::string environment :
       {"PCL_MS_HUGE_PAGES=0", "GLIBC_TUNABLES=glibc.malloc.hugetlb=0",
        "LD_PRELOAD=/nonexistent/vgpreload_core-amd64-linux.so",
        "PROBE_ON_REQUEST=1 PCL_MS_HUGE_PAGES=1 GLIBC_TUNABLES=glibc.malloc.hugetlb=0"}) {
    runProbe(environment);
    EXPECT_EQ(starts_, 1) << environment;
    EXPECT_FALSE(contains(stdout_, "hugetlb=1")) << environment << "\n" << stdout_;
  }
}

} // namespace
