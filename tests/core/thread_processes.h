// SPDX-License-Identifier: GPL-3.0-or-later
// Threads standing in for the processes of a shared run (docs/algorithm.md,
// "Across processes"), so that the collective code is checked in every
// build, sanitizers included, without MPI: by the tests and a fuzz target.
#pragma once

#include <pcl_ms/process_group.h>

#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace pcl_ms_test {

/// What the "processes" share: a barrier and one posted pointer each.
class Hub {
public:
  explicit Hub(int processes) : processes_(processes), posted_(processes, nullptr) {}

  void wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    const std::size_t generation = generation_;
    if (++waiting_ == processes_) {
      waiting_ = 0;
      ++generation_;
      changed_.notify_all();
    } else {
      changed_.wait(lock, [&] { return generation_ != generation; });
    }
  }
  int processes() const { return processes_; }
  std::vector<void *> &posted() { return posted_; }

private:
  const int processes_;
  std::vector<void *> posted_;
  std::mutex mutex_;
  std::condition_variable changed_;
  int waiting_ = 0;
  std::size_t generation_ = 0;
};

/// pcl_ms::ProcessGroup over a Hub: each call posts this process's data,
/// reads everyone's after a barrier, and waits again before returning.
class ThreadGroup : public pcl_ms::ProcessGroup {
public:
  ThreadGroup(Hub &hub, int process) : hub_(hub), process_(process) {}
  int processes() const override { return hub_.processes(); }
  int process() const override { return process_; }
  void sum(std::vector<std::uint64_t> &values) override {
    combine(values, [](std::uint64_t a, std::uint64_t b) { return a + b; });
  }
  void minimum(std::vector<double> &values) override { combine(values, pcl_ms::orderFreeMinimum); }
  void maximum(std::vector<double> &values) override { combine(values, pcl_ms::orderFreeMaximum); }
  std::vector<unsigned char> gatherAll(const std::vector<unsigned char> &mine) override {
    std::vector<unsigned char> all;
    share(&mine, [&](int, const void *theirs) {
      const auto &bytes = *static_cast<const std::vector<unsigned char> *>(theirs);
      all.insert(all.end(), bytes.begin(), bytes.end());
    });
    return all;
  }
  std::vector<unsigned char>
  exchange(const std::vector<std::vector<unsigned char>> &outgoing) override {
    std::vector<unsigned char> received;
    share(&outgoing, [&](int, const void *theirs) {
      const auto &bytes =
          static_cast<const std::vector<std::vector<unsigned char>> *>(theirs)->at(process_);
      received.insert(received.end(), bytes.begin(), bytes.end());
    });
    return received;
  }

  /// Element-wise operation(mine, theirs) over all processes' `values`.
  template <typename Value, typename Operation>
  void combine(std::vector<Value> &values, Operation operation) {
    std::vector<Value> combined = values;
    share(&values, [&](int other, const void *theirs) {
      const auto &their_values = *static_cast<const std::vector<Value> *>(theirs);
      if (their_values.size() != values.size()) {
        // The code under test called one collective with different sizes:
        // its processes would disagree. Not an assertion, which would
        // leave the others waiting at the barrier.
        std::fprintf(stderr, "process %d combines %zu values, process %d %zu\n", other,
                     their_values.size(), process_, values.size());
        std::abort();
      }
      if (other != process_)
        for (std::size_t i = 0; i < values.size(); ++i)
          combined[i] = operation(combined[i], their_values[i]);
    });
    values = std::move(combined);
  }

private:
  /// Posts this process's data, lets read(other, data) see every process's
  /// after a barrier, and waits until all have read before returning.
  template <typename Read> void share(const void *mine, const Read &read) {
    hub_.posted()[process_] = const_cast<void *>(mine); // the others only read it
    hub_.wait();
    for (int other = 0; other < hub_.processes(); ++other)
      read(other, hub_.posted()[other]);
    hub_.wait();
  }

  Hub &hub_;
  int process_;
};

/// Runs run(group) on `processes` threads, one ThreadGroup each.
inline void onThreadProcesses(int processes,
                              const std::function<void(pcl_ms::ProcessGroup &)> &run) {
  Hub hub(processes);
  std::vector<ThreadGroup> groups;
  for (int p = 0; p < processes; ++p)
    groups.emplace_back(hub, p);
  std::vector<std::thread> threads;
  for (int p = 0; p < processes; ++p)
    threads.emplace_back([&, p] { run(groups[p]); });
  for (std::thread &thread : threads)
    thread.join();
}

} // namespace pcl_ms_test
