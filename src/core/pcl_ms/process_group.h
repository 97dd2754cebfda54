// SPDX-License-Identifier: GPL-3.0-or-later
// The collective operations of processes that share one run, each holding a
// part of the cloud (docs/algorithm.md, "Across processes"): MPI in
// pcl_ms_reconstruct_mpi, threads in the tests. Every call is collective:
// all processes make it, in the same order.
#pragma once

#include <cstdint>
#include <vector>

namespace pcl_ms {

class ProcessGroup {
public:
  virtual ~ProcessGroup() = default;
  virtual int processes() const = 0;
  virtual int process() const = 0;
  /// Element-wise over all processes; every process gets the result.
  virtual void sum(std::vector<std::uint64_t> &values) = 0;
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
