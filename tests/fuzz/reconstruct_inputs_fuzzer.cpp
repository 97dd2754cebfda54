// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for what pcl_ms::reconstruct takes besides the points:
// normals (NaN, Inf, zero, any length), a subset of records (negative, out
// of range, repeated), initial triangles in either mode (invalid, repeated,
// degenerate, three on an edge), a viewpoint (any float), non-manifold seams
// and the medial axis, on the clouds of fuzz_reconstruct. A run must end with
// a mesh over the selected valid records that keeps every fixed initial
// triangle, a 2-manifold unless seams are allowed (or fixed triangles meet
// at a vertex only), and a consistent medial axis, or with a
// ReconstructionError.
#include "fuzz_clouds.h"

#include <pcl_ms/reconstruct.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <vector>

namespace pcl_ms_fuzz {

/// A normal component from one byte: the special values, or [-1, 1].
inline float normalComponent(std::uint8_t byte) {
  if (byte == 255)
    return std::numeric_limits<float>::quiet_NaN();
  if (byte == 254)
    return std::numeric_limits<float>::infinity();
  return byte == 0 ? 0.0f : (static_cast<int>(byte) - 128) / 127.0f;
}

inline void checkMedialAxis(const pcl_ms::MedialAxis &axis) {
  const std::size_t nodes = axis.node_positions.size();
  if (axis.node_radii.size() != nodes || axis.node_side.size() != nodes)
    broken("one radius and one side per medial-axis node");
  for (std::size_t i = 0; i < nodes; ++i)
    if (!axis.node_positions[i].allFinite() || !(axis.node_radii[i] >= 0) ||
        axis.node_side[i] > pcl_ms::MedialAxis::open)
      broken("medial-axis nodes are finite, with a radius and a side");
  for (const auto &curve : axis.curves)
    if (curve[0] >= curve[1] || curve[1] >= nodes)
      broken("medial-axis curves join two nodes, the smaller first");
  if (!std::is_sorted(axis.curves.begin(), axis.curves.end()))
    broken("medial-axis curves are sorted");
}

/// The target's body (see PCL_MS_FUZZ_TARGET).
inline int reconstructInputsOneInput(const std::uint8_t *data, std::size_t size) {
  ByteReader bytes(data, size);
  const std::uint8_t options = bytes.byte(), more = bytes.byte();
  pcl_ms::Parameters parameters;
  parameters.allow_non_manifold = (options & 1) != 0;
  parameters.use_normals = (options & 2) != 0;
  parameters.compute_medial_axis = (options & 4) != 0;
  const bool with_viewpoint = (options & 8) != 0, with_indices = (options & 16) != 0;
  const int initial_mode = (options >> 5) & 3; // 0: none, 1: fixed, 2 and 3: preferred
  parameters.grid_buckets = (options & 128) ? 2 : 0;
  parameters.num_threads = (more & 1) ? 2 : 1;
  parameters.min_points_for_threads = 0; // the parallel loops on tiny clouds too
  parameters.fill_holes_max_edges = (more & 2) ? 0 : 8;
  constexpr double normal_weights[4] = {1.0, 0.0, 4.0, 0.5};
  parameters.normal_weight = normal_weights[(more >> 2) & 3];
  parameters.rho = 1.0 + (more >> 4);

  if (with_viewpoint)
    parameters.viewpoint = {{bytes.rawFloat(), bytes.rawFloat(), bytes.rawFloat()}};
  std::vector<std::int64_t> indices;
  if (with_indices) {
    const int count = bytes.byte() % 64;
    for (int i = 0; i < count; ++i)
      indices.push_back(static_cast<std::int8_t>(bytes.byte())); // negative ones too
  }
  std::vector<pcl_ms::Triangle> initial;
  if (initial_mode != 0) {
    const int count = bytes.byte() % 16;
    for (int i = 0; i < count; ++i) {
      const pcl_ms::VertexIndex a = bytes.byte() % 128, b = bytes.byte() % 128,
                                c = bytes.byte() % 128;
      initial.push_back({a, b, c});
    }
    parameters.initial_triangles_mode = initial_mode == 1 ? pcl_ms::InitialTrianglesMode::fixed
                                                          : pcl_ms::InitialTrianglesMode::preferred;
  }
  // Normals cycle through a few bytes; none at all when there are none.
  std::vector<std::uint8_t> normal_bytes(bytes.byte() % 16);
  for (std::uint8_t &byte : normal_bytes)
    byte = bytes.byte();
  const std::vector<float> xyz = buildCloud(bytes);
  std::vector<float> normals;
  if (!normal_bytes.empty())
    for (std::size_t i = 0; i < xyz.size(); ++i)
      normals.push_back(normalComponent(normal_bytes[i % normal_bytes.size()]));

  pcl_ms::PointView view;
  view.xyz = xyz.data();
  view.size = xyz.size() / 3;
  view.normals = normals.empty() ? nullptr : normals.data();
  if (with_indices)
    view.indices = pcl_ms::IndexList(indices);
  pcl_ms::Result result;
  try {
    result = initial_mode != 0 ? pcl_ms::reconstruct(view, parameters, initial)
                               : pcl_ms::reconstruct(view, parameters);
  } catch (const pcl_ms::ReconstructionError &) {
    return 0; // a clear error is an allowed outcome
  }

  std::vector<bool> selected;
  if (with_indices) {
    selected.assign(view.size, false);
    for (std::int64_t index : indices)
      selected[static_cast<std::size_t>(index)] = true; // all valid, or it threw
  }
  // Fixed triangles are never undone: where they meet at a vertex only (in
  // the user's records, or once repeated points are merged) and the surface
  // does not join their fans, that vertex stays a pinch.
  const bool fixed = initial_mode == 1;
  const pcl_ms::MeshTopologyReport topology =
      checkMesh(xyz, selected, result, !parameters.allow_non_manifold && !fixed);
  if (fixed) {
    // By corner positions: a repeated point's triangles use its first record.
    using Corners = std::array<std::array<float, 3>, 3>;
    auto corners = [&](const pcl_ms::Triangle &triangle) {
      Corners sorted;
      for (int k = 0; k < 3; ++k)
        sorted[k] = {xyz[3 * triangle[k]], xyz[3 * triangle[k] + 1], xyz[3 * triangle[k] + 2]};
      std::sort(sorted.begin(), sorted.end());
      return sorted;
    };
    std::vector<Corners> kept;
    for (const pcl_ms::Triangle &triangle : result.triangles)
      kept.push_back(corners(triangle));
    std::sort(kept.begin(), kept.end());
    std::map<std::array<float, 3>, int> fixed_corner_uses;
    for (const pcl_ms::Triangle &triangle : initial) {
      const Corners position = corners(triangle);
      if (!std::binary_search(kept.begin(), kept.end(), position))
        broken("fixed initial triangles stay in the surface");
      for (const auto &corner : position)
        ++fixed_corner_uses[corner];
    }
    if (!parameters.allow_non_manifold) {
      const auto shared_corners = std::count_if(fixed_corner_uses.begin(), fixed_corner_uses.end(),
                                                [](const auto &use) { return use.second > 1; });
      if (topology.non_manifold_edges != 0 ||
          topology.non_manifold_vertices > static_cast<std::size_t>(shared_corners))
        broken("the mesh is a 2-manifold but where fixed triangles meet at a vertex only");
    }
  }
  if (parameters.compute_medial_axis && result.medial_axis)
    checkMedialAxis(*result.medial_axis);
  return 0;
}

} // namespace pcl_ms_fuzz

PCL_MS_FUZZ_TARGET(pcl_ms_fuzz::reconstructInputsOneInput)
