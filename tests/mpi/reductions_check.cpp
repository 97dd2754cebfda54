// SPDX-License-Identifier: GPL-3.0-or-later
// Run under mpirun: every rank must get the same bits from MpiProcessGroup's
// minimum and maximum, with a NaN on any one rank and zeros of both signs,
// as tests/core/test_process_group.cpp asks of the functions themselves.
// A rank that sees otherwise says so and exits non-zero.
#include "mpi_process_group.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

} // namespace

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int failures = 0;
  {
    pcl_ms_mpi::MpiProcessGroup group(MPI_COMM_WORLD);
    const int p = group.process(), processes = group.processes();
    for (int with_nan = 0; with_nan < processes; ++with_nan) {
      // Entry 0: NaN on one rank, its number on the others. Entry 1: zeros,
      // -0 on even ranks. Entry 2: the rank's number.
      std::vector<double> maxima{p == with_nan ? std::nan("") : p, p % 2 == 0 ? -0.0 : 0.0,
                                 static_cast<double>(p)};
      std::vector<double> minima = maxima;
      group.maximum(maxima);
      group.minimum(minima);
      const bool right = std::isnan(maxima[0]) && std::isnan(minima[0]) &&
                         sameBits(maxima[1], processes > 1 ? 0.0 : -0.0) &&
                         sameBits(minima[1], -0.0) && maxima[2] == processes - 1 && minima[2] == 0;
      if (!right) {
        std::fprintf(
            stderr, "FAIL: rank %d of %d, NaN on rank %d: maximum %g %g %g, minimum %g %g %g\n", p,
            processes, with_nan, maxima[0], maxima[1], maxima[2], minima[0], minima[1], minima[2]);
        ++failures;
      }
    }
  }
  MPI_Finalize();
  return failures == 0 ? 0 : 1;
}
