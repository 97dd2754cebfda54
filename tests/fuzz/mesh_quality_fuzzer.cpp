// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the mesh metrics of pcl_ms_evaluate and
// pcl_ms_compare (pcl_ms/mesh_quality.h) on two meshes built from the
// fuzzer's bytes: vertices in the shapes of fuzz_reconstruct (NaN, Inf,
// repeated, co-spherical, huge and tiny), triangles with indices out of
// range, repeated corners, duplicates and non-manifold edges. The reports
// must be consistent and every ratio and distance in its range.
#include "fuzz_clouds.h"

#include <pcl_ms/mesh_quality.h>

#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

namespace {

using pcl_ms_fuzz::broken;

/// Triangles over `vertex_count` vertices, indices up to two past the end.
std::vector<pcl_ms::Triangle> buildTriangles(pcl_ms_fuzz::ByteReader &bytes,
                                             std::size_t vertex_count) {
  std::vector<pcl_ms::Triangle> triangles(bytes.byte() % 48);
  for (pcl_ms::Triangle &triangle : triangles)
    for (pcl_ms::VertexIndex &v : triangle)
      v = static_cast<pcl_ms::VertexIndex>(bytes.byte() % (vertex_count + 2));
  return triangles;
}

bool isShare(double value) { return value >= 0 && value <= 1; }

std::vector<Eigen::Vector3d> toVertices(const std::vector<float> &xyz) {
  std::vector<Eigen::Vector3d> vertices;
  for (std::size_t i = 0; i + 2 < xyz.size(); i += 3)
    vertices.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
  return vertices;
}

void checkTopology(const pcl_ms::MeshTopologyReport &report, std::size_t vertices,
                   std::size_t triangles) {
  if (report.vertices != vertices || report.triangles != triangles ||
      report.referenced_vertices > vertices || report.invalid_triangles > triangles ||
      report.degenerate_triangles > triangles || report.duplicate_triangles > triangles ||
      report.components > triangles)
    broken("topology counts stay within the mesh");
  if (report.boundary_edges > report.edges || report.non_manifold_edges > report.edges ||
      report.non_manifold_vertices > vertices)
    broken("edge and vertex counts stay within the mesh");
  if (report.boundary_loop_lengths.size() != report.boundary_loops ||
      report.open_boundary_chains > report.boundary_loops ||
      std::accumulate(report.boundary_loop_lengths.begin(), report.boundary_loop_lengths.end(),
                      std::size_t{0}) != report.boundary_edges)
    broken("boundary curves share out the boundary edges");
  if (report.non_orientable_components > report.components ||
      report.orientable != (report.non_orientable_components == 0))
    broken("orientability agrees with its count");
  // A triangle's smallest angle is at most 60 degrees, up to rounding.
  constexpr double largest_smallest_angle = 60 + 1e-9;
  if (!isShare(report.used_vertex_fraction) || !isShare(report.share_min_angle_below_10deg) ||
      !(report.median_min_angle_deg >= 0 && report.median_min_angle_deg <= largest_smallest_angle))
    broken("shares and angles in range");
}

void checkDistances(const pcl_ms::DistanceStats &stats) {
  if (!(stats.mean >= 0 && stats.p95 >= 0 && stats.max >= 0))
    broken("distances are >= 0");
  // The mean of equal distances can round a little above them.
  constexpr double summation_rounding = 1e-12;
  if (std::isfinite(stats.max) &&
      !(stats.mean <= stats.max * (1 + summation_rounding) && stats.p95 <= stats.max))
    broken("mean and p95 are at most the max");
}

} // namespace

namespace pcl_ms_fuzz {

/// The target's body (see PCL_MS_FUZZ_TARGET).
inline int meshQualityOneInput(const std::uint8_t *data, std::size_t size) {
  ByteReader bytes(data, size);
  pcl_ms::ReferenceOptions options;
  const std::uint8_t settings = bytes.byte();
  options.surface_samples = settings & 63; // the deterministic samples come on top
  options.position_tolerance = (settings & 64) ? 1e-3 : 0.0;
  options.area_weighted_statistics = (settings & 128) != 0;
  // Both meshes take their triangles first: the vertex shapes read to the end.
  const std::uint8_t shared_vertices = bytes.byte() & 1;
  std::vector<std::uint8_t> triangle_bytes(bytes.byte() % 128);
  for (std::uint8_t &byte : triangle_bytes)
    byte = bytes.byte();
  const std::vector<Eigen::Vector3d> vertices = toVertices(buildCloud(bytes));
  // The reference: the same vertices (a mesh against a variant of itself),
  // or every other one.
  std::vector<Eigen::Vector3d> reference_vertices = vertices;
  if (!shared_vertices)
    for (std::size_t i = 0; i < reference_vertices.size(); i += 2)
      reference_vertices[i] *= 1.0 + 1e-3 * static_cast<double>(i);
  ByteReader triangle_reader(triangle_bytes.data(), triangle_bytes.size());
  const std::vector<pcl_ms::Triangle> triangles = buildTriangles(triangle_reader, vertices.size());
  const std::vector<pcl_ms::Triangle> reference_triangles =
      buildTriangles(triangle_reader, reference_vertices.size());

  checkTopology(pcl_ms::analyzeMesh(vertices, triangles), vertices.size(), triangles.size());
  const pcl_ms::ReferenceReport report = pcl_ms::compareWithReference(
      vertices, triangles, reference_vertices, reference_triangles, options);
  if (report.triangles != triangles.size() ||
      report.reference_triangles != reference_triangles.size() ||
      report.recovered_reference_triangles > report.reference_triangles ||
      report.triangles_in_reference > report.triangles)
    broken("triangle counts stay within the meshes");
  if (!isShare(report.recall) || !isShare(report.precision) || !isShare(report.fscore_0_1) ||
      !isShare(report.fscore_0_5))
    broken("recall, precision and F-scores are shares");
  if (!(report.reference_diagonal >= 0))
    broken("the reference diagonal is >= 0");
  checkDistances(report.to_reference);
  checkDistances(report.from_reference);
  return 0;
}

} // namespace pcl_ms_fuzz

PCL_MS_FUZZ_TARGET(pcl_ms_fuzz::meshQualityOneInput)
