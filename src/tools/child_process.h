// SPDX-License-Identifier: GPL-3.0-or-later
//
// Runs a piece of work in a forked child process so that its peak memory is
// measured on its own, not mixed with the caller's or other methods'. Used by
// the benchmarks and pcl_ms_compare.
#pragma once

#include <functional>
#include <string>

namespace pcl_ms_tools {

struct ChildOutcome {
  bool ok = false;     // the work returned normally and its bytes arrived
  std::string payload; // what the work returned
  std::string error;   // one line when !ok: the exception text or how the child died
  /// Peak resident memory of the child (VmHWM from /proc, or ru_maxrss if the
  /// child died before reading it), in MiB. The child starts as a copy of the
  /// caller, so this includes the caller's resident memory at the fork.
  double peak_mb = 0;
  /// The child's resident memory when it started (VmRSS), in MiB: roughly
  /// the caller's share of peak_mb, so peak_mb - start_mb is what the work
  /// added whatever the caller held. 0 where unknown.
  double start_mb = 0;
};

/// Runs `work` in a forked child and returns its bytes through a pipe. An
/// exception in the child becomes `error`, so does a crash (the signal) or
/// an exit. Call it only while the caller has no other threads running:
/// a forked child gets just the calling thread.
ChildOutcome runInChild(const std::function<std::string()> &work);

/// This process's peak resident memory (VmHWM) in MiB, 0 where unknown.
double peakResidentMb();
/// This process's resident memory now (VmRSS) in MiB, 0 where unknown.
double residentMb();

} // namespace pcl_ms_tools
