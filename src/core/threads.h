// SPDX-License-Identifier: GPL-3.0-or-later
// The task arena for Parameters::num_threads. Internal to the library: not
// installed.
#pragma once

#include <tbb/task_arena.h>

namespace pcl_ms {
namespace detail {

/// An arena of num_threads threads, or of TBB's default when it is 0
/// (automatic). Parallel loops run inside it use no more threads than that.
inline tbb::task_arena threadArena(int num_threads) {
  return tbb::task_arena(num_threads > 0 ? num_threads : tbb::task_arena::automatic);
}

} // namespace detail
} // namespace pcl_ms
