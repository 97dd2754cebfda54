// SPDX-License-Identifier: GPL-3.0-or-later
// A list made ascending with each value once: the step before every lookup by
// binary search in the core. Internal: not installed.
#pragma once

#include <algorithm>
#include <vector>

namespace pcl_ms {
namespace detail {

/// Sorts `values` and drops repeats, in place.
template <typename T> void sortUnique(std::vector<T> &values) {
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
}

} // namespace detail
} // namespace pcl_ms
