// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4's edge scan over a triangle list held in parts (edges_in_parts.h;
// docs/algorithm.md, "Finishing in parts").
#include "edges_in_parts.h"

#include "finish_steps.h"
#include "process_bytes.h"

#include <algorithm>
#include <stdexcept>

namespace pcl_ms {
namespace detail {
namespace {

/// An edge of a triangle, sent to the edge's judge.
struct EdgeUse {
  EdgeKey key;
  std::uint64_t triangle;
  bool operator<(const EdgeUse &other) const {
    return key < other.key || (key == other.key && triangle < other.triangle);
  }
};

/// The judge's answer to the process of `triangle`: its neighbour across
/// `key`, or no_neighbour_in_parts for a boundary edge.
struct EdgeVerdict {
  EdgeKey key;
  std::uint64_t triangle;
  std::uint64_t across;
};

} // namespace

MeshEdgesPart meshEdgesInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                               std::uint64_t vertex_count, ProcessGroup &group) {
  const auto processes = static_cast<std::size_t>(group.processes());
  const std::vector<std::uint64_t> firsts =
      runFirsts(mine.size(), first, group, "meshEdgesInParts (triangles)");
  std::uint64_t outside = 0;
  for (const Triangle &t : mine)
    for (VertexIndex v : t)
      outside += v >= vertex_count;
  if (totalOver(outside, group) > 0)
    throw std::invalid_argument("meshEdgesInParts: a triangle has a corner beyond the points");

  const auto judgeOf = [&](EdgeKey key) {
    return static_cast<std::size_t>(std::uint64_t{lowVertex(key)} * processes / vertex_count);
  };
  const auto holderOf = [&](std::uint64_t triangle) { return runHolding(firsts, triangle); };

  std::vector<std::vector<EdgeUse>> uses_out(processes);
  for (std::size_t t = 0; t < mine.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const EdgeKey key = edgeKey(mine[t][k], mine[t][(k + 1) % 3]);
      uses_out[judgeOf(key)].push_back({key, first + t});
    }
  std::vector<EdgeUse> uses;
  deliver(uses_out, group, [&](const EdgeUse &use) { uses.push_back(use); });
  parallelSort(uses.begin(), uses.end(), std::less<EdgeUse>());

  // Judged in key order; the judges own increasing ranges of lower
  // vertices, so each holder receives its verdicts in key order too.
  std::vector<std::vector<EdgeVerdict>> verdicts_out(processes);
  bool crowded = false;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key)
      ++j;
    const EdgeKey key = uses[i].key;
    if (j - i == 1) {
      verdicts_out[holderOf(uses[i].triangle)].push_back(
          {key, uses[i].triangle, no_neighbour_in_parts});
    } else if (j - i == 2) {
      const std::uint64_t t = uses[i].triangle, u = uses[i + 1].triangle;
      verdicts_out[holderOf(t)].push_back({key, t, u});
      verdicts_out[holderOf(u)].push_back({key, u, t});
    } else {
      crowded = true;
    }
    i = j;
  }
  std::vector<EdgeUse>().swap(uses);

  MeshEdgesPart part;
  part.neighbours.assign(3 * mine.size(), no_neighbour_in_parts);
  deliver(verdicts_out, group, [&](const EdgeVerdict &verdict) {
    if (verdict.across == no_neighbour_in_parts) {
      part.boundary.push_back(verdict.key);
      part.boundary_triangle.push_back(verdict.triangle);
    } else {
      const std::size_t t = verdict.triangle - first;
      part.neighbours[3 * t + slotOf(mine[t], verdict.key)] = verdict.across;
    }
  });
  packSlots(part.neighbours, no_neighbour_in_parts);
  part.crowded = totalOver(crowded ? 1 : 0, group) > 0;
  return part;
}

} // namespace detail
} // namespace pcl_ms
