// SPDX-License-Identifier: GPL-3.0-or-later
// Small checks on indexed triangles shared by the two halves of the metrics
// (mesh_quality_topology.cpp, mesh_quality_reference.cpp). Internal.
#pragma once

#include <pcl_ms/types.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <Eigen/Core>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace pcl_ms {
namespace metrics_detail {

// Exact predicates for the degeneracy test.
using PredicateKernel = CGAL::Exact_predicates_inexact_constructions_kernel;

inline bool isFinite(const Eigen::Vector3d &point) { return point.allFinite(); }

inline bool indicesInRange(const Triangle &triangle, std::size_t vertex_count) {
  return triangle[0] < vertex_count && triangle[1] < vertex_count && triangle[2] < vertex_count;
}

inline bool hasRepeatedIndex(const Triangle &triangle) {
  return triangle[0] == triangle[1] || triangle[1] == triangle[2] || triangle[0] == triangle[2];
}

/// Indices in range is a precondition.
inline bool isDegenerate(const std::vector<Eigen::Vector3d> &vertices, const Triangle &triangle) {
  if (hasRepeatedIndex(triangle))
    return true;
  const Eigen::Vector3d &a = vertices[triangle[0]];
  const Eigen::Vector3d &b = vertices[triangle[1]];
  const Eigen::Vector3d &c = vertices[triangle[2]];
  // The exact predicate does not accept NaN or infinity.
  if (!isFinite(a) || !isFinite(b) || !isFinite(c))
    return true;
  return CGAL::collinear(PredicateKernel::Point_3(a.x(), a.y(), a.z()),
                         PredicateKernel::Point_3(b.x(), b.y(), b.z()),
                         PredicateKernel::Point_3(c.x(), c.y(), c.z()));
}

inline std::uint64_t edgeKey(VertexIndex a, VertexIndex b) {
  const VertexIndex low = std::min(a, b);
  const VertexIndex high = std::max(a, b);
  return (static_cast<std::uint64_t>(low) << 32) | high;
}

inline Triangle sortedCorners(Triangle triangle) {
  std::sort(triangle.begin(), triangle.end());
  return triangle;
}

} // namespace metrics_detail
} // namespace pcl_ms
