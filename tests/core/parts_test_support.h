// SPDX-License-Identifier: GPL-3.0-or-later
// Helpers of the tests of lists held in parts by several processes: the
// runs and slices each process holds.
#pragma once

#include "components_in_parts.h"
#include "core_test_support.h"
#include "edges_in_parts.h"
#include "points_from_homes.h"

#include <pcl_ms/process_group.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace pcl_ms_test {

/// Items [begin, end) of `all`: one process's run or slice.
template <typename Value>
std::vector<Value> sliceOf(const std::vector<Value> &all, std::size_t begin, std::size_t end) {
  return std::vector<Value>(all.begin() + static_cast<std::ptrdiff_t>(begin),
                            all.begin() + static_cast<std::ptrdiff_t>(end));
}

/// Where slice p of `count` items among `processes` starts (p = processes:
/// the end), cut unevenly: the first slice empty, the later ones larger,
/// so that the slices do not line up with runs cut evenly.
inline std::size_t unevenCut(std::size_t count, std::size_t p, std::size_t processes) {
  return count * p * p / (processes * processes);
}

/// Local scales that vary from point to point, so that the size limit of
/// hole filling refuses some fillings of the bunny's holes.
inline std::vector<float> varyingScales(std::size_t count) {
  std::vector<float> scales(count);
  for (std::size_t v = 0; v < count; ++v)
    scales[v] = static_cast<float>(0.0012 * (1.5 + std::sin(0.37 * static_cast<double>(v))));
  return scales;
}

/// The first 20,000 triangles of the bunny's reference mesh but those
/// `taken_out(t)` marks: holes, boundary edges along the patch's cut and
/// round them, manifold edges elsewhere.
template <typename TakenOut>
std::vector<pcl_ms::Triangle> bunnyPatchWithout(const TakenOut &taken_out) {
  const std::vector<pcl_ms::Triangle> &all = bunnyReference().triangles;
  std::vector<pcl_ms::Triangle> patch;
  for (std::size_t t = 0; t < 20000; ++t)
    if (!taken_out(t))
      patch.push_back(all[t]);
  return patch;
}

/// What the orientation steps in parts start from, for one process's run.
struct OrientationInputs {
  pcl_ms::detail::MeshEdgesPart edges;
  pcl_ms::detail::ComponentsPart components;
  pcl_ms::detail::CornerPoints corners;
};

/// The edge scan, the components and the corner points of run `mine` (from
/// triangle `first` on), with its home slice of the points from `home_first`.
inline OrientationInputs orientationInputs(const std::vector<pcl_ms::Triangle> &mine,
                                           std::uint64_t first,
                                           const std::vector<Eigen::Vector3d> &home,
                                           std::uint64_t home_first, std::uint64_t point_count,
                                           pcl_ms::ProcessGroup &group) {
  OrientationInputs inputs;
  inputs.edges = pcl_ms::detail::meshEdgesInParts(mine, first, point_count, group);
  inputs.components = pcl_ms::detail::componentsInParts(mine, first, inputs.edges, group);
  inputs.corners = pcl_ms::detail::cornerPointsFromHomes(mine, home, home_first, group);
  return inputs;
}

} // namespace pcl_ms_test
