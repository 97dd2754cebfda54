// SPDX-License-Identifier: GPL-3.0-or-later
// The optional time limit of a reconstruction (Parameters::time_limit_seconds):
// checked at stage boundaries and, every few thousand steps, inside the long
// loops, so that a run past its limit stops with an error instead of a mesh.
#pragma once

#include <pcl_ms/reconstruct.h>

#include <chrono>
#include <cstdint>
#include <sstream>
#include <string>

namespace pcl_ms {

/// Thrown when a run exceeds Parameters::time_limit_seconds. No partial mesh
/// is returned: the run is abandoned where it is.
class TimeLimitExceeded : public ReconstructionError {
public:
  using ReconstructionError::ReconstructionError;
};

class Deadline {
public:
  using Clock = std::chrono::steady_clock;

  /// No limit when seconds <= 0.
  explicit Deadline(double seconds)
      : limit_seconds_(seconds), has_limit_(seconds > 0),
        end_(has_limit_ ? Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(seconds))
                        : Clock::time_point::max()) {}

  /// Throws TimeLimitExceeded, naming `stage`, once the limit has passed.
  void check(const char *stage) const {
    if (has_limit_ && Clock::now() >= end_)
      throw TimeLimitExceeded(message(stage));
  }

  /// For tight loops: reads the clock only every 4096th call.
  void checkEvery(std::uint32_t &counter, const char *stage) const {
    if (has_limit_ && (++counter & 4095u) == 0)
      check(stage);
  }

private:
  std::string message(const char *stage) const {
    std::ostringstream text;
    text << "time limit of " << limit_seconds_ << " s exceeded during " << stage
         << ": no mesh was produced";
    return text.str();
  }

  double limit_seconds_;
  bool has_limit_;
  Clock::time_point end_;
};

} // namespace pcl_ms
