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

/// How the points are cut into home slices: evenly, or as unevenCut does.
enum class HomeCut { even, uneven };

/// One process's home slice: its first point's index, its points and, when
/// the test has local scales, theirs.
struct HomeSlice {
  std::size_t begin = 0;
  std::vector<Eigen::Vector3d> points;
  std::vector<float> scales;
};

/// Home slice p of `points` (and of `scales` when it is not empty) among
/// `processes`.
inline HomeSlice homeSlice(const std::vector<Eigen::Vector3d> &points, std::size_t p, int processes,
                           HomeCut cut, const std::vector<float> &scales = {}) {
  const auto count = static_cast<std::size_t>(processes);
  const auto at = [&](std::size_t q) {
    return cut == HomeCut::even ? points.size() * q / count : unevenCut(points.size(), q, count);
  };
  HomeSlice home;
  home.begin = at(p);
  home.points = sliceOf(points, home.begin, at(p + 1));
  if (!scales.empty())
    home.scales = sliceOf(scales, home.begin, at(p + 1));
  return home;
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

/// What the orientation steps in parts start from, for one process: its
/// run of the triangles, their edge scan, components and corner points.
struct OrientationInputs {
  std::vector<pcl_ms::Triangle> mine;
  pcl_ms::detail::MeshEdgesPart edges;
  pcl_ms::detail::ComponentsPart components;
  pcl_ms::detail::CornerPoints corners;
};

/// The orientation inputs of `group`'s process when the triangles are cut
/// into runs at `cuts` and the points into home slices by `home_cut`.
inline OrientationInputs orientationInputs(const std::vector<pcl_ms::Triangle> &triangles,
                                           const std::vector<std::size_t> &cuts,
                                           const std::vector<Eigen::Vector3d> &points,
                                           HomeCut home_cut, pcl_ms::ProcessGroup &group) {
  const auto p = static_cast<std::size_t>(group.process());
  const HomeSlice home = homeSlice(points, p, group.processes(), home_cut);
  OrientationInputs inputs;
  inputs.mine = sliceOf(triangles, cuts[p], cuts[p + 1]);
  inputs.edges = pcl_ms::detail::meshEdgesInParts(inputs.mine, cuts[p], points.size(), group);
  inputs.components = pcl_ms::detail::componentsInParts(inputs.mine, cuts[p], inputs.edges, group);
  inputs.corners =
      pcl_ms::detail::cornerPointsFromHomes(inputs.mine, home.points, home.begin, group);
  return inputs;
}

} // namespace pcl_ms_test
