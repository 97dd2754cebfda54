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

/// Whether the kernel backs madvise'd memory with huge pages and makes them
/// at the fault ("madvise" or "always" for both), so that a test may expect them.
bool hugePagesMadeAtFault() {
  auto selected = [](const char *path) {
    std::ifstream file(path);
    std::string line;
    std::getline(file, line);
    const auto open = line.find('['), close = line.find(']');
    return open == std::string::npos ? std::string() : line.substr(open + 1, close - open - 1);
  };
  const std::string enabled = selected("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string defrag = selected("/sys/kernel/mm/transparent_hugepage/defrag");
  return (enabled == "always" || enabled == "madvise") &&
         (defrag == "always" || defrag == "madvise" || defrag == "defer+madvise");
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

/// Regions on or off while it lives, whatever the probe chose (each test
/// sets what it checks; the machine's own choice comes back after it).
class RegionsChosen {
public:
  explicit RegionsChosen(bool on) : before_(detail::regionsInUse()) { detail::useRegions(on); }
  ~RegionsChosen() { detail::useRegions(before_); }
  RegionsChosen(const RegionsChosen &) = delete;
  RegionsChosen &operator=(const RegionsChosen &) = delete;

private:
  bool before_;
};

} // namespace

TEST(HugePages, SmallBlocksComeFromTheHeapAndLargeOnesFromRegionsThatGoWithThem) {
  if (!PCL_MS_HUGE_PAGE_REGIONS)
    GTEST_SKIP() << "regions are off in this build (AddressSanitizer or not Linux)";
  const RegionsChosen regions(true);
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
  const RegionsChosen regions(true);
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
  const RegionsChosen regions(true);
  HugePageAllocator<char> allocator;
  const std::size_t bytes = std::size_t(8) << 20;
  char *block = allocator.allocate(bytes);
  std::memset(block, 1, bytes);
  EXPECT_GE(hugePagesKbAt(block), 2048);
  allocator.deallocate(block, bytes);
}

TEST(HugePages, ReconstructionLeavesNoRegionBehind) {
  const RegionsChosen regions(true);
  const std::size_t before = detail::regionsMapped();
  const std::vector<float> xyz = fibonacciSphere(20000);
  const Result result = reconstruct(viewOf(xyz), Parameters());
  EXPECT_GT(result.triangles.size(), 39000u);
  EXPECT_EQ(detail::regionsMapped(), before);
}

// Where the probe finds first writes cheap, a large block comes from the
// heap: aligned like a region's, mapping none.
TEST(HugePages, WithoutRegionsLargeBlocksComeFromTheHeap) {
  if (!PCL_MS_HUGE_PAGE_REGIONS)
    GTEST_SKIP() << "regions are off in this build (AddressSanitizer or not Linux)";
  const RegionsChosen regions(false);
  const std::size_t before = detail::regionsMapped();
  HugePageAllocator<double> allocator;
  const std::size_t count = (std::size_t(1) << 20) / sizeof(double);
  std::vector<double *> blocks;
  for (int i = 0; i < 4; ++i) {
    blocks.push_back(allocator.allocate(count));
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(blocks.back()) % 64, 0u);
    std::fill(blocks.back(), blocks.back() + count, double(i));
  }
  EXPECT_EQ(detail::regionsMapped(), before);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(blocks[i][0], double(i));
    EXPECT_EQ(blocks[i][count - 1], double(i));
    allocator.deallocate(blocks[i], count);
  }
}

// A block goes back where it came from, even when the choice changed since.
TEST(HugePages, BlocksGoBackWhereTheyCameFromAfterTheChoiceChanges) {
  if (!PCL_MS_HUGE_PAGE_REGIONS)
    GTEST_SKIP() << "regions are off in this build (AddressSanitizer or not Linux)";
  const std::size_t before = detail::regionsMapped();
  HugePageAllocator<char> allocator;
  const std::size_t bytes = std::size_t(1) << 20;
  char *from_region = nullptr, *from_heap = nullptr;
  {
    const RegionsChosen regions(true);
    from_region = allocator.allocate(bytes);
  }
  EXPECT_EQ(detail::regionsMapped(), before + 1);
  {
    const RegionsChosen regions(false);
    from_heap = allocator.allocate(bytes);
    std::memset(from_heap, 2, bytes);
    std::memset(from_region, 1, bytes);
    allocator.deallocate(from_region, bytes);
  }
  EXPECT_EQ(detail::regionsMapped(), before);
  {
    const RegionsChosen regions(true);
    EXPECT_EQ(from_heap[bytes - 1], 2);
    allocator.deallocate(from_heap, bytes);
  }
  EXPECT_EQ(detail::regionsMapped(), before);
}

// The large arrays written in full as soon as they exist (the candidates,
// the greedy's states) get huge pages the same way.
TEST(HugePages, ArraysResizedForWritingAreOnHugePagesWhereTheKernelMakesThem) {
  if (!hugePagesMadeAtFault())
    GTEST_SKIP() << "no transparent huge pages at fault here";
  std::vector<std::uint64_t> values;
  detail::resizeForWriting(values, std::size_t(1) << 20); // 8 MB: 3 whole huge pages at least
  std::fill(values.begin(), values.end(), 5u);
  EXPECT_GE(hugePagesKbAt(values.data() + values.size() / 2), 2048);
  EXPECT_EQ(values.back(), 5u);
}
