// SPDX-License-Identifier: GPL-3.0-or-later
// Process 0's share of the finishing steps over a list held in parts
// (docs/algorithm.md, "Finishing in parts"): the sides of the edges between
// runs paired up, and the pieces they name numbered.
#pragma once

#include "numbering.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <vector>

namespace pcl_ms {
namespace detail {

/// Sorts the sides of edges between runs (each names its `triangle` and the
/// triangle `across`) so that those between the same two triangles come
/// together, the lower triangle's first, and calls visit(begin, end) for
/// each such group: one side from each triangle per edge they share (two
/// triangles on the same three corners share three).
template <typename Side, typename Visit>
void forEachTrianglePair(std::vector<Side> &sides, const Visit &visit) {
  const auto pairOf = [](const Side &side) {
    return std::make_tuple(std::min(side.triangle, side.across),
                           std::max(side.triangle, side.across), side.triangle);
  };
  std::sort(sides.begin(), sides.end(),
            [&](const Side &a, const Side &b) { return pairOf(a) < pairOf(b); });
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i;
    while (j < sides.size() && std::get<0>(pairOf(sides[j])) == std::get<0>(pairOf(sides[i])) &&
           std::get<1>(pairOf(sides[j])) == std::get<1>(pairOf(sides[i])))
      ++j;
    visit(i, j);
    i = j;
  }
}

/// Pieces (named by their first triangles) numbered in ascending order, so
/// that a parity forest over the numbers, whose roots are its smallest
/// numbers, roots each component at its first triangle as one process's
/// forest does.
using PieceNumbers = Numbering<std::uint64_t>;

} // namespace detail
} // namespace pcl_ms
