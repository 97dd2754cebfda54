// SPDX-License-Identifier: GPL-3.0-or-later
// Huge-page regions for CGAL's triangulation containers
// (src/core/huge_page_allocator.h).
#include "core_test_support.h"
#include "huge_page_allocator.h"
#include "populate_pages.h"

#include <pcl_ms/reconstruct.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using namespace pcl_ms;
using detail::HugePageAllocator;
using pcl_ms_test::fibonacciSphere;
using pcl_ms_test::viewOf;

namespace {

/// The selected value of a transparent huge page setting, the word in
/// brackets in the file; empty where there is no such file.
std::string selectedSetting(const char *path) {
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);
  const auto open = line.find('['), close = line.find(']');
  return open == std::string::npos || close == std::string::npos
             ? std::string()
             : line.substr(open + 1, close - open - 1);
}

/// Whether the kernel backs madvise'd memory with huge pages and makes them
/// at the fault ("madvise" or "always" for both), so that a test may expect them.
bool hugePagesMadeAtFault() {
  const std::string enabled = selectedSetting("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string defrag = selectedSetting("/sys/kernel/mm/transparent_hugepage/defrag");
  return (enabled == "always" || enabled == "madvise") &&
         (defrag == "always" || defrag == "madvise" || defrag == "defer+madvise");
}

/// Whether the kernel makes huge pages only where they are asked for.
bool hugePagesOnlyOnAdvice() {
  return selectedSetting("/sys/kernel/mm/transparent_hugepage/enabled") == "madvise";
}

/// AnonHugePages (kB) of the mapping that holds `address`, from /proc/self/smaps.
long hugePagesKbAt(const void *address) {
  const auto target = reinterpret_cast<std::uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = begin <= target && target < end;
      continue;
    }
    if (inside && line.compare(0, 14, "AnonHugePages:") == 0)
      return std::stol(line.substr(14));
  }
  return -1;
}

/// Huge pages asked for, not asked for or left to the probe while it lives,
/// whatever was chosen before (that choice comes back after it).
class HugePagesChosen {
public:
  explicit HugePagesChosen(detail::HugePagesChoice choice) : before_(detail::hugePagesChoice()) {
    detail::setHugePagesChoice(choice);
  }
  ~HugePagesChosen() { detail::setHugePagesChoice(before_); }
  HugePagesChosen(const HugePagesChosen &) = delete;
  HugePagesChosen &operator=(const HugePagesChosen &) = delete;

private:
  detail::HugePagesChoice before_;
};

} // namespace

TEST(HugePages, SmallBlocksComeFromTheHeapAndLargeOnesFromRegionsThatGoWithThem) {
  if (!PCL_MS_HUGE_PAGE_REGIONS)
    GTEST_SKIP() << "regions are off in this build (AddressSanitizer or not Linux)";
  const std::size_t before = detail::regionsMapped();
  HugePageAllocator<double> allocator;
  double *small = allocator.allocate(100);
  EXPECT_EQ(detail::regionsMapped(), before);
  // Enough 1 MB blocks to fill more than one region, and one larger than a region.
  std::vector<double *> blocks;
  const std::size_t count = (std::size_t(1) << 20) / sizeof(double);
  for (int i = 0; i < 40; ++i) {
    blocks.push_back(allocator.allocate(count));
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(blocks.back()) % 64, 0u);
    std::memset(blocks.back(), i, count * sizeof(double));
  }
  double *large = allocator.allocate(5 * count * 16);
  large[5 * count * 16 - 1] = 1.0;
  EXPECT_GE(detail::regionsMapped(), before + 3);
  // No block overlaps another: each still holds what was written into it.
  for (int i = 0; i < 40; ++i) {
    const auto *bytes = reinterpret_cast<const unsigned char *>(blocks[i]);
    EXPECT_EQ(bytes[0], i);
    EXPECT_EQ(bytes[count * sizeof(double) - 1], i);
  }
  for (double *block : blocks)
    allocator.deallocate(block, count);
  allocator.deallocate(large, 5 * count * 16);
  allocator.deallocate(small, 100);
  EXPECT_EQ(detail::regionsMapped(), before);
}

TEST(HugePages, BlocksFreedOnAnotherThreadLeaveNoRegionWhenTheirThreadEnds) {
  if (!PCL_MS_HUGE_PAGE_REGIONS)
    GTEST_SKIP() << "regions are off in this build (AddressSanitizer or not Linux)";
  const std::size_t before = detail::regionsMapped();
  const std::size_t count = (std::size_t(1) << 18) / sizeof(int);
  std::vector<int *> blocks(8, nullptr);
  std::thread owner([&] {
    HugePageAllocator<int> allocator;
    for (int *&block : blocks) {
      block = allocator.allocate(count);
      block[count - 1] = 7;
    }
  });
  owner.join();
  // The owner is gone; its region lives on while its blocks do.
  EXPECT_EQ(detail::regionsMapped(), before + 1);
  std::thread other([&] {
    HugePageAllocator<int> allocator;
    for (int *block : blocks) {
      EXPECT_EQ(block[count - 1], 7);
      allocator.deallocate(block, count);
    }
  });
  other.join();
  EXPECT_EQ(detail::regionsMapped(), before);
}

TEST(HugePages, LargeBlocksAreOnHugePagesWhereTheKernelMakesThem) {
  if (!PCL_MS_HUGE_PAGE_REGIONS || !hugePagesMadeAtFault())
    GTEST_SKIP() << "no transparent huge pages at fault here";
  const HugePagesChosen huge_pages(detail::HugePagesChoice::pay);
  HugePageAllocator<char> allocator;
  const std::size_t bytes = std::size_t(8) << 20;
  char *block = allocator.allocate(bytes);
  std::memset(block, 1, bytes);
  EXPECT_GE(hugePagesKbAt(block), 2048);
  allocator.deallocate(block, bytes);
}

TEST(HugePages, ReconstructionLeavesNoRegionBehind) {
  const std::size_t before = detail::regionsMapped();
  const std::vector<float> xyz = fibonacciSphere(20000);
  const Result result = reconstruct(viewOf(xyz), Parameters());
  EXPECT_GT(result.triangles.size(), 39000u);
  EXPECT_EQ(detail::regionsMapped(), before);
}

// Where huge pages do not pay, a large block is on 4 kB pages, also where
// the kernel would make huge pages unasked.
TEST(HugePages, WhereTheyDoNotPayLargeBlocksAreOnSmallPages) {
  if (!PCL_MS_HUGE_PAGE_REGIONS)
    GTEST_SKIP() << "regions are off in this build (AddressSanitizer or not Linux)";
  const HugePagesChosen huge_pages(detail::HugePagesChoice::do_not_pay);
  const std::size_t before = detail::regionsMapped();
  HugePageAllocator<char> allocator;
  const std::size_t bytes = std::size_t(8) << 20;
  char *block = allocator.allocate(bytes);
  EXPECT_EQ(detail::regionsMapped(), before + 1);
  std::memset(block, 3, bytes);
  EXPECT_EQ(hugePagesKbAt(block), 0);
  EXPECT_EQ(block[bytes - 1], 3);
  allocator.deallocate(block, bytes);
  EXPECT_EQ(detail::regionsMapped(), before);
}

// The large arrays written in full as soon as they exist (the candidates,
// the greedy's states) get huge pages the same way.
TEST(HugePages, ArraysResizedForWritingAreOnHugePagesWhereTheKernelMakesThem) {
  if (!hugePagesMadeAtFault())
    GTEST_SKIP() << "no transparent huge pages at fault here";
  const HugePagesChosen huge_pages(detail::HugePagesChoice::pay);
  std::vector<std::uint64_t> values;
  detail::resizeForWriting(values, std::size_t(1) << 20); // 8 MB: 3 whole huge pages at least
  std::fill(values.begin(), values.end(), 5u);
  EXPECT_GE(hugePagesKbAt(values.data() + values.size() / 2), 2048);
  EXPECT_EQ(values.back(), 5u);
}

// Where huge pages do not pay, the arrays do not ask for them. 40 MB: above
// glibc's largest threshold for mapping a block of its own, so the pages
// are fresh, not ones an earlier test had on huge pages.
TEST(HugePages, WhereTheyDoNotPayArraysResizedForWritingAreOnSmallPages) {
  if (!hugePagesOnlyOnAdvice())
    GTEST_SKIP() << "the kernel does not make huge pages only on advice here";
  const HugePagesChosen huge_pages(detail::HugePagesChoice::do_not_pay);
  std::vector<std::uint64_t> values;
  detail::resizeForWriting(values, std::size_t(5) << 20);
  std::fill(values.begin(), values.end(), 6u);
  EXPECT_EQ(hugePagesKbAt(values.data() + values.size() / 2), 0);
  EXPECT_EQ(values.back(), 6u);
}

// The probe runs only where huge pages could matter: an array below one
// huge page holds none, so populating it leaves the choice open, and a
// small cloud never pays for the probe.
TEST(HugePages, OnlyArraysOfAHugePageOrMoreRunTheProbe) {
#if !defined(__linux__)
  GTEST_SKIP() << "no probe outside Linux";
#endif
  const HugePagesChosen huge_pages(detail::HugePagesChoice::undecided);
  std::vector<std::uint64_t> small;
  detail::resizeForWriting(small, detail::huge_page_bytes / sizeof(std::uint64_t) / 2);
  EXPECT_EQ(detail::hugePagesChoice(), detail::HugePagesChoice::undecided);
  std::vector<std::uint64_t> large;
  detail::resizeForWriting(large, detail::huge_page_bytes / sizeof(std::uint64_t) * 2);
  EXPECT_NE(detail::hugePagesChoice(), detail::HugePagesChoice::undecided);
}
