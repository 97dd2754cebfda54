// SPDX-License-Identifier: GPL-3.0-or-later
// Pages faulted in before the first write (src/core/populate_pages.h).
#include "populate_pages.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

using namespace pcl_ms::detail;

namespace {

std::vector<std::uint32_t> pattern(std::size_t count) {
  std::vector<std::uint32_t> values(count);
  for (std::size_t i = 0; i < count; ++i)
    values[i] = static_cast<std::uint32_t>(i * 2654435761u);
  return values;
}

} // namespace

TEST(PopulatePages, ContentsStayAsTheyWere) {
  std::vector<std::uint32_t> values = pattern(std::size_t(1) << 20);
  const std::vector<std::uint32_t> expected = values;
  populateCapacity(values);
  // A range that starts and ends inside pages: only whole pages are asked for.
  populateForWriting(reinterpret_cast<const char *>(values.data()) + 3,
                     values.size() * sizeof(std::uint32_t) - 7);
  EXPECT_EQ(values, expected);
}

TEST(PopulatePages, ResizeKeepsTheElementsAndValueInitialisesTheNewOnes) {
  std::vector<std::uint32_t> values = {7, 8, 9};
  resizeForWriting(values, std::size_t(1) << 20);
  ASSERT_EQ(values.size(), std::size_t(1) << 20);
  EXPECT_EQ(values[0], 7u);
  EXPECT_EQ(values[1], 8u);
  EXPECT_EQ(values[2], 9u);
  for (std::size_t i = 3; i < values.size(); ++i)
    ASSERT_EQ(values[i], 0u) << "at " << i;
}

TEST(PopulatePages, ExactCopyIsTheListAtItsSize) {
  std::vector<std::uint32_t> gathered;
  gathered.reserve(std::size_t(1) << 20);
  const std::vector<std::uint32_t> values = pattern(300000);
  gathered.assign(values.begin(), values.end());
  const std::vector<std::uint32_t> copy = exactCopy(gathered);
  EXPECT_EQ(copy, values);
  EXPECT_EQ(copy.capacity(), copy.size());
  EXPECT_TRUE(exactCopy(std::vector<std::uint32_t>()).empty());
}

#if defined(__linux__)
// The pages of a fresh mapping are in memory after the call, before any write,
// where the kernel has MADV_POPULATE_WRITE (Linux 5.14); small ranges are left.
TEST(PopulatePages, FaultsTheWholePagesIn) {
  const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  const std::size_t pages = 256;
  auto resident = [&](void *start) {
    std::vector<unsigned char> flags(pages);
    EXPECT_EQ(mincore(start, pages * page, flags.data()), 0);
    std::size_t count = 0;
    for (unsigned char flag : flags)
      count += flag & 1;
    return count;
  };
  void *probe =
      mmap(nullptr, pages * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(probe, MAP_FAILED);
  const bool supported = madvise(probe, page, 23 /* MADV_POPULATE_WRITE */) == 0;
  munmap(probe, pages * page);
  if (!supported)
    GTEST_SKIP() << "this kernel has no MADV_POPULATE_WRITE";

  void *start =
      mmap(nullptr, pages * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(start, MAP_FAILED);
  madvise(start, pages * page, MADV_NOHUGEPAGE);
  EXPECT_EQ(resident(start), 0u);
  populateForWriting(start, (min_populated_bytes / page - 1) * page);
  EXPECT_EQ(resident(start), 0u) << "a range below the threshold is left alone";
  // From one byte into the first page to one byte into the last: the whole
  // pages in between.
  populateForWriting(static_cast<char *>(start) + 1, (pages - 1) * page);
  EXPECT_EQ(resident(start), pages - 2);
  munmap(start, pages * page);
}
#endif
