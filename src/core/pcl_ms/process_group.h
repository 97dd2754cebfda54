// SPDX-License-Identifier: GPL-3.0-or-later
// The collective operations of processes that share one run, each holding a
// part of the cloud (docs/algorithm.md, "Across processes"): MPI in
// pcl_ms_reconstruct_mpi, threads in the tests. Every call is collective:
// all processes make it, in the same order.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace pcl_ms {

/// The element-wise combinations of minimum() and maximum(), for every
/// implementation. Each gives the same bits whatever order the processes'
/// values meet in: NaN wins, as one quiet NaN (std::max and MPI_MAX let the
/// order decide, so processes would disagree with one process's run); of
/// equal zeros, -0 is the smaller.
inline double orderFreeMinimum(double a, double b) {
  if (std::isnan(a) || std::isnan(b))
    return std::numeric_limits<double>::quiet_NaN();
  if (a == b)
    return std::signbit(a) ? a : b;
  return a < b ? a : b;
}
inline double orderFreeMaximum(double a, double b) {
  if (std::isnan(a) || std::isnan(b))
    return std::numeric_limits<double>::quiet_NaN();
  if (a == b)
    return std::signbit(a) ? b : a;
  return a > b ? a : b;
}

class ProcessGroup {
public:
  virtual ~ProcessGroup() = default;
  virtual int processes() const = 0;
  virtual int process() const = 0;
  /// Element-wise over all processes; every process gets the result.
  virtual void sum(std::vector<std::uint64_t> &values) = 0;
  /// With orderFreeMinimum and orderFreeMaximum.
  virtual void minimum(std::vector<double> &values) = 0;
  virtual void maximum(std::vector<double> &values) = 0;
  /// Every process's bytes, concatenated in process order, on every process.
  virtual std::vector<unsigned char> gatherAll(const std::vector<unsigned char> &mine) = 0;
  /// outgoing[p] goes to process p (one entry per process); returns what
  /// each process sent to this one, concatenated in process order.
  virtual std::vector<unsigned char>
  exchange(const std::vector<std::vector<unsigned char>> &outgoing) = 0;
};

/// One process alone: every collective is the identity.
class OneProcess : public ProcessGroup {
public:
  int processes() const override { return 1; }
  int process() const override { return 0; }
  void sum(std::vector<std::uint64_t> &) override {}
  void minimum(std::vector<double> &) override {}
  void maximum(std::vector<double> &) override {}
  std::vector<unsigned char> gatherAll(const std::vector<unsigned char> &mine) override {
    return mine;
  }
  std::vector<unsigned char>
  exchange(const std::vector<std::vector<unsigned char>> &outgoing) override {
    return outgoing.at(0);
  }
};

} // namespace pcl_ms
