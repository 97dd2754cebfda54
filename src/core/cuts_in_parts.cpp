// SPDX-License-Identifier: GPL-3.0-or-later
// The twist repair's cut and the bow-tie split over a triangle list held in
// parts (cuts_in_parts.h; docs/algorithm.md, "Finishing in parts").
#include "cuts_in_parts.h"

#include "finish_steps.h"
#include "process_bytes.h"
#include "sort_unique.h"

#include <algorithm>
#include <iterator>
#include <stdexcept>

namespace pcl_ms {
namespace detail {
namespace {

/// A triangle at a vertex to check, to the process grouping its fans: its number in the list
/// the cut leaves, and its corners.
struct AtVertex {
  VertexIndex vertex;
  std::uint64_t triangle;
  Triangle corners;
};

/// The corners of the marked triangles, ascending, each once.
std::vector<VertexIndex> cornersOf(const std::vector<Triangle> &triangles,
                                   const std::vector<std::uint8_t> &marked) {
  std::vector<VertexIndex> corners;
  for (std::size_t t = 0; t < triangles.size(); ++t)
    if (marked[t])
      corners.insert(corners.end(), triangles[t].begin(), triangles[t].end());
  detail::sortUnique(corners);
  return corners;
}

/// A process's round: the triangles at each of its vertices to check grouped into
/// fans, and those of all fans but the one to keep.
std::vector<std::uint64_t> bowTieTriangles(std::vector<AtVertex> &at) {
  std::sort(at.begin(), at.end(), [](const AtVertex &a, const AtVertex &b) {
    return a.vertex < b.vertex || (a.vertex == b.vertex && a.triangle < b.triangle);
  });
  std::vector<std::uint64_t> going;
  std::vector<Triangle> corners;
  std::vector<std::uint32_t> around, drop;
  for (std::size_t i = 0; i < at.size();) {
    std::size_t j = i;
    while (j < at.size() && at[j].vertex == at[i].vertex)
      ++j;
    // The vertex's triangles numbered by their place, in ascending order.
    corners.clear();
    around.clear();
    drop.clear();
    for (std::size_t k = i; k < j; ++k) {
      around.push_back(static_cast<std::uint32_t>(corners.size()));
      corners.push_back(at[k].corners);
    }
    dropBowTieFans(at[i].vertex, around.data(), around.data() + around.size(), corners, {}, drop);
    for (std::uint32_t local : drop)
      going.push_back(at[i + local].triangle);
    i = j;
  }
  detail::sortUnique(going);
  return going;
}

} // namespace

CutPart cutInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                   const std::vector<std::uint64_t> &to_cut, ProcessGroup &group,
                   const std::vector<VertexIndex> &also_check) {
  const auto processes = static_cast<std::size_t>(group.processes());
  const std::size_t count = mine.size();
  const std::vector<std::uint64_t> firsts = runFirsts(count, first, group, "cutInParts");
  const bool beyond = std::any_of(to_cut.begin(), to_cut.end(),
                                  [&](std::uint64_t t) { return t >= firsts.back(); });
  if (totalOver(beyond ? 1 : 0, group) > 0)
    throw std::invalid_argument("cutInParts: a triangle to cut is beyond the list");

  // The cut: each number to its holder.
  std::vector<std::uint8_t> cut(count, 0);
  {
    std::vector<std::vector<std::uint64_t>> cut_out(processes);
    for (std::uint64_t t : to_cut)
      cut_out[runHolding(firsts, t)].push_back(t);
    deliver(cut_out, group, [&](std::uint64_t t) { cut[static_cast<std::size_t>(t - first)] = 1; });
  }
  CutPart part;
  part.touched = cornersOf(mine, cut);
  std::vector<VertexIndex> check;
  std::set_union(part.touched.begin(), part.touched.end(), also_check.begin(), also_check.end(),
                 std::back_inserter(check));
  std::vector<Triangle> left;
  for (std::size_t t = 0; t < count; ++t)
    if (!cut[t])
      left.push_back(mine[t]);
  const std::vector<std::uint64_t> left_firsts = firstsOf(countsOf(left.size(), group));
  const std::uint64_t left_first = left_firsts[static_cast<std::size_t>(group.process())];

  // Bow-ties: rounds over the vertices to check, first the corners of the
  // cut (and `also_check`), then those of the triangles the last round split
  // off. Each vertex's fans are grouped by process v mod processes: the
  // first round after the buckets checks every seam point.
  std::vector<std::uint8_t> split_off(left.size(), 0);
  while (true) {
    std::vector<VertexIndex> all_check;
    gatherAtZero<VertexIndex>(
        check.size(), [&](std::size_t i) { return check[i]; },
        [&](std::size_t, VertexIndex v) { all_check.push_back(v); }, group);
    detail::sortUnique(all_check);
    if (totalOver(all_check.size(), group) == 0)
      break;
    fromZeroToAll(all_check, group);
    std::vector<std::vector<AtVertex>> at_out(processes);
    for (std::size_t t = 0; t < left.size(); ++t)
      if (!split_off[t])
        for (VertexIndex v : left[t])
          if (std::binary_search(all_check.begin(), all_check.end(), v))
            at_out[v % processes].push_back({v, left_first + t, left[t]});
    std::vector<AtVertex> at;
    deliver(at_out, group, [&](const AtVertex &one) { at.push_back(one); });
    std::vector<std::vector<std::uint64_t>> going_out(processes);
    for (std::uint64_t t : bowTieTriangles(at))
      going_out[runHolding(left_firsts, t)].push_back(t);
    std::vector<std::uint8_t> going(left.size(), 0);
    deliver(going_out, group,
            [&](std::uint64_t t) { going[static_cast<std::size_t>(t - left_first)] = 1; });
    check = cornersOf(left, going);
    for (std::size_t t = 0; t < left.size(); ++t)
      split_off[t] |= going[t];
  }

  // The places of what went: cut, or left and split off.
  for (std::size_t t = 0, l = 0; t < count; ++t) {
    if (cut[t])
      part.dropped.push_back(t);
    else if (split_off[l++])
      part.dropped.push_back(t);
  }
  const std::vector<VertexIndex> split_corners = cornersOf(left, split_off);
  // What stays, in place: no third copy of the run beside `mine` and `left`.
  std::size_t kept = 0;
  for (std::size_t t = 0; t < left.size(); ++t)
    if (!split_off[t])
      left[kept++] = left[t];
  left.resize(kept);
  part.kept = std::move(left);
  std::vector<VertexIndex> touched;
  std::set_union(part.touched.begin(), part.touched.end(), split_corners.begin(),
                 split_corners.end(), std::back_inserter(touched));
  part.touched = std::move(touched);
  const std::vector<std::uint64_t> kept_firsts = firstsOf(countsOf(part.kept.size(), group));
  part.first = kept_firsts[static_cast<std::size_t>(group.process())];
  part.split_off = left_firsts.back() - kept_firsts.back();
  return part;
}

} // namespace detail
} // namespace pcl_ms
