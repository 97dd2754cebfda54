// SPDX-License-Identifier: GPL-3.0-or-later
// The corners of a triangulation's facet or cell in ascending order of
// their points' indices: the order the scaffold measures them in, so that
// nothing it computes depends on the order in which CGAL stores them
// (docs/algorithm.md, "Candidate order"). Internal to the library: not
// installed.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>

namespace pcl_ms {
namespace detail {

/// `handles` (3 or 4 vertex handles, each info() its point's index) in
/// ascending index order, by a network of minima and maxima on keys (index,
/// slot): no branches on the indices, which come in no order.
template <typename Handle, std::size_t N>
std::array<Handle, N> byIndex(const std::array<Handle, N> &handles) {
  static_assert(N == 3 || N == 4, "a facet's or a cell's corners");
  std::array<std::uint64_t, N> keys;
  for (std::size_t k = 0; k < N; ++k)
    keys[k] = std::uint64_t{handles[k]->info()} << 2 | k;
  auto order = [&](std::size_t j, std::size_t k) {
    const std::uint64_t low = std::min(keys[j], keys[k]);
    keys[k] = std::max(keys[j], keys[k]);
    keys[j] = low;
  };
  if constexpr (N == 3) {
    order(0, 1);
    order(1, 2);
    order(0, 1);
  } else {
    order(0, 1);
    order(2, 3);
    order(0, 2);
    order(1, 3);
    order(1, 2);
  }
  std::array<Handle, N> sorted;
  for (std::size_t k = 0; k < N; ++k)
    sorted[k] = handles[keys[k] & 3];
  return sorted;
}

} // namespace detail
} // namespace pcl_ms
