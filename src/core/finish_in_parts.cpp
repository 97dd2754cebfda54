// SPDX-License-Identifier: GPL-3.0-or-later
// Finishing over a triangle list held in parts (finish_in_parts.h;
// docs/algorithm.md, "Finishing in parts").
#include "finish_in_parts.h"

#include "components_in_parts.h"
#include "conflicts_in_parts.h"
#include "cuts_in_parts.h"
#include "edges_in_parts.h"
#include "finish_steps.h"
#include "holes_in_parts.h"
#include "points_from_homes.h"
#include "process_bytes.h"
#include "sides_in_parts.h"
#include "twists_in_parts.h"

#include <optional>
#include <utility>

namespace pcl_ms {
namespace detail {

FinishedPart finishInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                           const std::vector<Eigen::Vector3d> &home_points,
                           const std::vector<float> &home_scales, std::uint64_t home_first,
                           int fill_holes_max_edges, double rho, const Eigen::Vector3d *viewpoint,
                           ProcessGroup &group) {
  const std::uint64_t point_count = totalOver(home_points.size(), group);
  const bool last = group.process() + 1 == group.processes();
  FinishedPart part;
  part.triangles = mine;
  part.first = first;
  // One scan of the edges; fillings and cuts update it from then on (a
  // crowded list is scanned again).
  MeshEdgesPart edges = meshEdgesInParts(part.triangles, part.first, point_count, group);
  const auto scanAgain = [&](const std::vector<Triangle> &triangles, std::uint64_t from) {
    edges = MeshEdgesPart(); // not held while the new ones are made
    edges = meshEdgesInParts(triangles, from, point_count, group);
  };
  std::optional<CornerPoints> corners;
  // Small holes filled, then every component oriented; returns the
  // triangles to cut where a twist is a fold or a crumple.
  const auto fillThenOrient = [&](int max_edges, const std::vector<VertexIndex> *around) {
    HolesPart holes = fillHolesInParts(part.triangles, edges, home_points, home_scales, home_first,
                                       max_edges, rho, around, group);
    part.boundary_loops = std::move(holes.loops);
    part.holes_filled += holes.filled;
    const std::size_t first_new = part.triangles.size();
    if (holes.filled > 0) {
      if (last)
        part.triangles.insert(part.triangles.end(), holes.filling.begin(), holes.filling.end());
      if (edges.crowded)
        scanAgain(part.triangles, part.first);
      else
        addTrianglesToEdgesInParts(edges, part.triangles, part.first, first_new, group);
    }
    ComponentsPart components = componentsInParts(part.triangles, part.first, edges, group);
    // After a cut, only the filling can bring corners that are not held yet.
    if (corners)
      addCornerPointsFromHomes(*corners, part.triangles, first_new, home_points, home_first, group);
    else
      corners = cornerPointsFromHomes(part.triangles, home_points, home_first, group);
    const std::vector<std::uint8_t> side_turns =
        sideTurnsInParts(part.triangles, part.first, edges, components, *corners, viewpoint, group);
    const TwistsPart twists =
        twistForestInParts(part.triangles, part.first, edges, components, *corners, group);
    for (std::size_t t = 0; t < part.triangles.size(); ++t)
      if (side_turns[t] ^ twists.flipped[t])
        std::swap(part.triangles[t][1], part.triangles[t][2]);
    std::vector<std::uint64_t> cuts =
        conflictCutsInParts(part.triangles, part.first, edges, components, *corners,
                            twists.conflicts, viewpoint, group);
    part.component = std::move(components.component);
    part.orientable = std::move(components.orientable);
    return cuts;
  };
  std::vector<std::uint64_t> to_cut = fillThenOrient(fill_holes_max_edges, nullptr);
  for (int round = 0; round < max_untwist_rounds && totalOver(to_cut.size(), group) > 0; ++round) {
    const std::uint64_t before = totalOver(part.triangles.size(), group);
    CutPart cut = cutInParts(part.triangles, part.first, to_cut, group);
    if (edges.crowded)
      scanAgain(cut.kept, cut.first);
    else
      dropFromEdgesInParts(edges, part.triangles, part.first, cut.dropped, group);
    part.triangles = std::move(cut.kept);
    part.first = cut.first;
    part.twist_triangles_removed += before - totalOver(part.triangles.size(), group);
    // The loops that the cut opened are ours to close, whatever the user's limit.
    to_cut = fillThenOrient(max_untwist_loop_edges, &cut.touched);
  }
  return part;
}

} // namespace detail
} // namespace pcl_ms
