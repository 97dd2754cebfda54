// SPDX-License-Identifier: GPL-3.0-or-later
// The minimum and maximum that processes sharing a run combine their figures
// with: whatever order the values meet in, every process must get the same
// bits as one process would, NaN and signed zeros included.
#include "thread_processes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Values whose order std::max and MPI_MAX leave to chance.
std::vector<double> awkwardValues() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  return {nan, -nan, std::nan("7"), 0.0, -0.0, 1.5, -2.0, inf, -inf, 5e-324};
}

TEST(ProcessGroup, MinimumAndMaximumGiveTheSameBitsInAnyOrder) {
  // Commutative and associative to the bit: then every order of combining
  // the processes' values gives the same result.
  const std::vector<double> values = awkwardValues();
  for (auto combine : {pcl_ms::orderFreeMinimum, pcl_ms::orderFreeMaximum})
    for (double a : values)
      for (double b : values) {
        EXPECT_TRUE(sameBits(combine(a, b), combine(b, a))) << a << ", " << b;
        for (double c : values)
          EXPECT_TRUE(sameBits(combine(combine(a, b), c), combine(a, combine(b, c))))
              << a << ", " << b << ", " << c;
      }
}

TEST(ProcessGroup, NaNWinsAndSignedZerosAreOrdered) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(std::isnan(pcl_ms::orderFreeMaximum(0.0, nan)));
  EXPECT_TRUE(std::isnan(pcl_ms::orderFreeMaximum(nan, 0.0)));
  EXPECT_TRUE(std::isnan(pcl_ms::orderFreeMinimum(1.0, nan)));
  EXPECT_TRUE(sameBits(pcl_ms::orderFreeMaximum(-0.0, 0.0), 0.0));
  EXPECT_TRUE(sameBits(pcl_ms::orderFreeMinimum(0.0, -0.0), -0.0));
  EXPECT_EQ(pcl_ms::orderFreeMaximum(1.0, 2.0), 2.0);
  EXPECT_EQ(pcl_ms::orderFreeMinimum(1.0, 2.0), 1.0);
}

TEST(ProcessGroup, ThreadProcessesCarryNaNFromAnyProcess) {
  // Entry 0: NaN on one process, its number on the others. Entry 1: zeros,
  // -0 on even processes. Entry 2: the process's number.
  for (int processes = 2; processes <= 4; ++processes)
    for (int with_nan = 0; with_nan < processes; ++with_nan) {
      std::vector<std::vector<double>> maxima(processes), minima(processes);
      pcl_ms_test::onThreadProcesses(processes, [&](pcl_ms::ProcessGroup &group) {
        const int p = group.process();
        std::vector<double> values{p == with_nan ? std::nan("") : p, p % 2 == 0 ? -0.0 : 0.0,
                                   static_cast<double>(p)};
        std::vector<double> copy = values;
        group.maximum(values);
        group.minimum(copy);
        maxima[p] = values;
        minima[p] = copy;
      });
      for (int p = 0; p < processes; ++p) {
        SCOPED_TRACE(testing::Message()
                     << processes << " processes, NaN on " << with_nan << ", seen by " << p);
        EXPECT_TRUE(std::isnan(maxima[p][0]));
        EXPECT_TRUE(std::isnan(minima[p][0]));
        EXPECT_TRUE(sameBits(maxima[p][1], 0.0));
        EXPECT_TRUE(sameBits(minima[p][1], -0.0));
        EXPECT_EQ(maxima[p][2], processes - 1);
        EXPECT_EQ(minima[p][2], 0);
      }
    }
}

} // namespace
