// SPDX-License-Identifier: GPL-3.0-or-later
// Distinct ids numbered 0, 1, ... in ascending order: the compact numbers
// by which process 0 of a finishing step in parts indexes what it was sent
// (docs/algorithm.md, "Finishing in parts"). Internal: not installed.
#pragma once

#include "sort_unique.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace pcl_ms {
namespace detail {

template <typename Id> class Numbering {
public:
  /// The distinct ids among those given, repeats allowed.
  explicit Numbering(std::vector<Id> ids) : ids_(std::move(ids)) { detail::sortUnique(ids_); }
  /// The number of `id`, one of the ids given.
  std::uint32_t operator()(Id id) const {
    return static_cast<std::uint32_t>(std::lower_bound(ids_.begin(), ids_.end(), id) -
                                      ids_.begin());
  }
  bool contains(Id id) const { return std::binary_search(ids_.begin(), ids_.end(), id); }
  /// The id numbered `number`.
  Id id(std::uint32_t number) const { return ids_[number]; }
  std::size_t size() const { return ids_.size(); }
  /// The ids, ascending.
  const std::vector<Id> &ids() const { return ids_; }

private:
  std::vector<Id> ids_;
};

} // namespace detail
} // namespace pcl_ms
