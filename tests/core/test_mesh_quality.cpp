// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh-quality metrics on small meshes whose answers are known by hand.
#include <pcl_ms/mesh_quality.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

namespace pcl_ms {
namespace {

struct Mesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Triangle> triangles;
};

// Outward-oriented tetrahedron on the unit corner: three right isosceles
// faces and one equilateral face.
Mesh tetrahedron() {
  return {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
          {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}}};
}

// Unit cube, vertex x + 2y + 4z, outward orientation, two triangles per face;
// the top face (z = 1) comes last.
Mesh cube() {
  Mesh mesh;
  for (int index = 0; index < 8; ++index)
    mesh.vertices.emplace_back(index & 1, (index >> 1) & 1, (index >> 2) & 1);
  mesh.triangles = {{0, 2, 3}, {0, 3, 1}, {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                    {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}, {4, 5, 7}, {4, 7, 6}};
  return mesh;
}

// Möbius strip of `segments` quads around a circle with a half twist: 2n
// vertices, 2n triangles, 4n edges, one boundary curve of 2n edges. All quads
// are oriented alike, so only the rung where the twist closes (t0-b0) is run
// the same way by both of its triangles.
Mesh mobiusStrip(int segments) {
  Mesh mesh;
  const double pi = std::acos(-1.0);
  for (int k = 0; k < segments; ++k) {
    const double around = 2 * pi * k / segments, twist = around / 2;
    for (double across : {0.3, -0.3}) // top t_k = 2k, bottom b_k = 2k + 1
      mesh.vertices.emplace_back((1 + across * std::cos(twist)) * std::cos(around),
                                 (1 + across * std::cos(twist)) * std::sin(around),
                                 across * std::sin(twist));
  }
  for (int k = 0; k < segments; ++k) {
    const VertexIndex top = 2 * k, bottom = 2 * k + 1;
    // After a full turn the half twist has swapped top and bottom.
    const bool last = k == segments - 1;
    const VertexIndex next_top = last ? 1 : 2 * k + 2, next_bottom = last ? 0 : 2 * k + 3;
    mesh.triangles.push_back({top, bottom, next_bottom});
    mesh.triangles.push_back({top, next_bottom, next_top});
  }
  return mesh;
}

// (n+1)^2 vertices on [0,1]^2 with z = height(x, y); quad (i, j) is split
// into two counter-clockwise triangles, rows of increasing y in order.
Mesh grid(int n, const std::function<double(double, double)> &height) {
  Mesh mesh;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = static_cast<double>(i) / n, y = static_cast<double>(j) / n;
      mesh.vertices.emplace_back(x, y, height(x, y));
    }
  auto at = [n](int i, int j) { return static_cast<VertexIndex>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return mesh;
}

Mesh flatGrid(int n) {
  return grid(n, [](double, double) { return 0.0; });
}

Mesh bumpyGrid(int n) {
  return grid(n, [](double x, double y) { return 0.1 * std::sin(3 * x) * std::cos(2 * y); });
}

MeshTopologyReport analyze(const Mesh &mesh) { return analyzeMesh(mesh.vertices, mesh.triangles); }

ReferenceReport compare(const Mesh &ours, const Mesh &reference,
                        const ReferenceOptions &options = {}) {
  return compareWithReference(ours.vertices, ours.triangles, reference.vertices,
                              reference.triangles, options);
}

// ---------------------------------------------------------------------------
// analyzeMesh

TEST(MeshQualityTopology, TetrahedronIsAClosedOrientedSphere) {
  const MeshTopologyReport report = analyze(tetrahedron());
  EXPECT_EQ(report.vertices, 4u);
  EXPECT_EQ(report.referenced_vertices, 4u);
  EXPECT_EQ(report.triangles, 4u);
  EXPECT_EQ(report.edges, 6u);
  EXPECT_EQ(report.boundary_edges, 0u);
  EXPECT_EQ(report.boundary_loops, 0u);
  EXPECT_TRUE(report.boundary_loop_lengths.empty());
  EXPECT_EQ(report.non_manifold_edges, 0u);
  EXPECT_EQ(report.non_manifold_vertices, 0u);
  EXPECT_EQ(report.components, 1u);
  EXPECT_EQ(report.euler_characteristic, 2);
  EXPECT_TRUE(report.orientable);
  EXPECT_EQ(report.non_orientable_components, 0u);
  EXPECT_EQ(report.inconsistently_oriented_edges, 0u);
  EXPECT_EQ(report.degenerate_triangles, 0u);
  EXPECT_EQ(report.duplicate_triangles, 0u);
  EXPECT_EQ(report.used_vertex_fraction, 1.0);
  // Min angles 45, 45, 45, 60: the two middle values are both 45.
  EXPECT_NEAR(report.median_min_angle_deg, 45.0, 1e-9);
  EXPECT_EQ(report.share_min_angle_below_10deg, 0.0);
}

TEST(MeshQualityTopology, FlippedTriangleIsInconsistentButOrientable) {
  Mesh mesh = tetrahedron();
  std::swap(mesh.triangles[2][0], mesh.triangles[2][1]);
  const MeshTopologyReport report = analyze(mesh);
  EXPECT_EQ(report.inconsistently_oriented_edges, 3u);
  EXPECT_TRUE(report.orientable);
  EXPECT_EQ(report.euler_characteristic, 2);
}

TEST(MeshQualityTopology, ClosedCube) {
  const MeshTopologyReport report = analyze(cube());
  EXPECT_EQ(report.edges, 18u);
  EXPECT_EQ(report.boundary_edges, 0u);
  EXPECT_EQ(report.euler_characteristic, 2);
  EXPECT_EQ(report.components, 1u);
  EXPECT_EQ(report.inconsistently_oriented_edges, 0u);
  EXPECT_NEAR(report.median_min_angle_deg, 45.0, 1e-9);
}

TEST(MeshQualityTopology, CubeWithoutOneFaceHasOneSquareHole) {
  Mesh mesh = cube();
  mesh.triangles.resize(10); // drop the top face
  const MeshTopologyReport report = analyze(mesh);
  EXPECT_EQ(report.vertices, 8u);
  EXPECT_EQ(report.referenced_vertices, 8u);
  EXPECT_EQ(report.triangles, 10u);
  EXPECT_EQ(report.edges, 17u);
  EXPECT_EQ(report.boundary_edges, 4u);
  EXPECT_EQ(report.boundary_loops, 1u);
  EXPECT_EQ(report.boundary_loop_lengths, std::vector<std::size_t>{4});
  EXPECT_EQ(report.open_boundary_chains, 0u);
  EXPECT_EQ(report.euler_characteristic, 1);
  EXPECT_EQ(report.components, 1u);
  EXPECT_TRUE(report.orientable);
  EXPECT_EQ(report.non_manifold_edges, 0u);
  EXPECT_EQ(report.non_manifold_vertices, 0u);
}

TEST(MeshQualityTopology, MobiusStripIsNotOrientable) {
  const MeshTopologyReport report = analyze(mobiusStrip(6));
  EXPECT_EQ(report.vertices, 12u);
  EXPECT_EQ(report.triangles, 12u);
  EXPECT_EQ(report.edges, 24u);
  EXPECT_EQ(report.boundary_edges, 12u);
  EXPECT_EQ(report.boundary_loops, 1u);
  EXPECT_EQ(report.boundary_loop_lengths, std::vector<std::size_t>{12});
  EXPECT_EQ(report.euler_characteristic, 0);
  EXPECT_EQ(report.components, 1u);
  EXPECT_FALSE(report.orientable);
  EXPECT_EQ(report.non_orientable_components, 1u);
  EXPECT_EQ(report.inconsistently_oriented_edges, 1u);
  EXPECT_EQ(report.non_manifold_edges, 0u);
  EXPECT_EQ(report.non_manifold_vertices, 0u);
  EXPECT_EQ(report.degenerate_triangles, 0u);
}

TEST(MeshQualityTopology, OnlyTheMobiusComponentIsNonOrientable) {
  Mesh mesh = mobiusStrip(6);
  const Mesh tet = tetrahedron();
  const auto offset = static_cast<VertexIndex>(mesh.vertices.size());
  for (const Eigen::Vector3d &vertex : tet.vertices)
    mesh.vertices.push_back(vertex + Eigen::Vector3d(5, 0, 0));
  for (const Triangle &triangle : tet.triangles)
    mesh.triangles.push_back({triangle[0] + offset, triangle[1] + offset, triangle[2] + offset});
  const MeshTopologyReport report = analyze(mesh);
  EXPECT_EQ(report.components, 2u);
  EXPECT_EQ(report.non_orientable_components, 1u);
  EXPECT_FALSE(report.orientable);
  EXPECT_EQ(report.euler_characteristic, 2);
}

TEST(MeshQualityTopology, TrianglesSharingOneVertexPinch) {
  // Interleaved indices: pairing the pinch's boundary edges by far vertex
  // (1-2, 3-4) instead of by fan (1-3, 2-4) would make one loop of six.
  const Mesh mesh{{{0, 0, 0}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}},
                  {{0, 1, 3}, {0, 2, 4}}};
  const MeshTopologyReport report = analyze(mesh);
  EXPECT_EQ(report.non_manifold_vertices, 1u);
  EXPECT_EQ(report.non_manifold_edges, 0u);
  EXPECT_EQ(report.components, 2u);
  EXPECT_EQ(report.edges, 6u);
  EXPECT_EQ(report.boundary_edges, 6u);
  // The pinch keeps the two triangles' boundaries apart.
  EXPECT_EQ(report.boundary_loops, 2u);
  EXPECT_EQ(report.boundary_loop_lengths, (std::vector<std::size_t>{3, 3}));
  EXPECT_EQ(report.open_boundary_chains, 0u);
  EXPECT_EQ(report.euler_characteristic, 1);
  EXPECT_TRUE(report.orientable);
}

TEST(MeshQualityTopology, TetrahedraTouchingAtOneVertex) {
  Mesh mesh = tetrahedron();
  // Point reflection through vertex 0 gives a second tetrahedron on vertex 0.
  const Mesh tet = tetrahedron();
  for (std::size_t v = 1; v < 4; ++v)
    mesh.vertices.push_back(-tet.vertices[v]);
  auto mapped = [](VertexIndex v) { return v == 0 ? VertexIndex{0} : v + 3; };
  for (const Triangle &triangle : tet.triangles)
    mesh.triangles.push_back({mapped(triangle[0]), mapped(triangle[1]), mapped(triangle[2])});
  const MeshTopologyReport report = analyze(mesh);
  EXPECT_EQ(report.non_manifold_vertices, 1u);
  EXPECT_EQ(report.components, 2u);
  EXPECT_EQ(report.boundary_edges, 0u);
  EXPECT_EQ(report.euler_characteristic, 3); // 7 - 12 + 8
  EXPECT_TRUE(report.orientable);
}

TEST(MeshQualityTopology, ThreeTrianglesOnOneEdge) {
  const Mesh mesh{{{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0}, {0.5, 0, 1}},
                  {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}};
  const MeshTopologyReport report = analyze(mesh);
  EXPECT_EQ(report.non_manifold_edges, 1u);
  // Vertices 0 and 1 lie on the non-manifold edge: counted there only.
  EXPECT_EQ(report.non_manifold_vertices, 0u);
  EXPECT_EQ(report.edges, 7u);
  EXPECT_EQ(report.boundary_edges, 6u);
  EXPECT_EQ(report.components, 1u);
  EXPECT_EQ(report.euler_characteristic, 1);
  // No two-triangle edge, hence no orientation constraint.
  EXPECT_TRUE(report.orientable);
  EXPECT_EQ(report.inconsistently_oriented_edges, 0u);
  // At vertices 0 and 1 the three boundary edges pair by far vertex: 2 with 3
  // (closed loop 0-2-1-3), and 4 is left over (open chain 0-4-1).
  EXPECT_EQ(report.boundary_loops, 2u);
  EXPECT_EQ(report.boundary_loop_lengths, (std::vector<std::size_t>{4, 2}));
  EXPECT_EQ(report.open_boundary_chains, 1u);
}

TEST(MeshQualityTopology, DegenerateAndDuplicateTriangles) {
  const Mesh mesh{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {3, 0, 0}, {2, 1e-12, 0}},
                  {
                      {0, 1, 2}, // fine
                      {0, 0, 1}, // repeated index
                      {3, 1, 0}, // exactly collinear
                      {0, 1, 4}, // nearly but not exactly collinear
                      {2, 1, 0}, // duplicate of the first, reversed
                      {1, 2, 0}, // duplicate of the first, rotated
                  }};
  const MeshTopologyReport report = analyze(mesh);
  EXPECT_EQ(report.degenerate_triangles, 2u);
  EXPECT_EQ(report.duplicate_triangles, 2u);
  EXPECT_EQ(report.triangles, 6u);
  EXPECT_EQ(report.invalid_triangles, 0u);
  // The repeated-index triangle is no 2-cell; the other five all hold edge 0-1.
  EXPECT_EQ(report.non_manifold_edges, 3u); // 0-1 (five faces), 1-2 and 0-2 (three each)
  // Min angles: 45 x 3, then 0, 0 (degenerate) and a tiny one: median 22.5.
  EXPECT_NEAR(report.median_min_angle_deg, 22.5, 1e-9);
  EXPECT_NEAR(report.share_min_angle_below_10deg, 0.5, 1e-15);
}

TEST(MeshQualityTopology, UnusedVerticesAndInvalidIndices) {
  Mesh mesh = tetrahedron();
  mesh.vertices.emplace_back(7, 7, 7);
  mesh.vertices.emplace_back(8, 8, 8);
  mesh.vertices.emplace_back(9, 9, 9);
  mesh.vertices.emplace_back(10, 10, 10);
  mesh.triangles.push_back({0, 1, 1000});
  const MeshTopologyReport report = analyze(mesh);
  EXPECT_EQ(report.vertices, 8u);
  EXPECT_EQ(report.referenced_vertices, 4u);
  EXPECT_EQ(report.used_vertex_fraction, 0.5);
  EXPECT_EQ(report.triangles, 5u);
  EXPECT_EQ(report.invalid_triangles, 1u);
  EXPECT_EQ(report.euler_characteristic, 2);
  EXPECT_EQ(report.boundary_edges, 0u);
}

TEST(MeshQualityTopology, EmptyMesh) {
  const MeshTopologyReport report = analyzeMesh({}, {});
  EXPECT_EQ(report.vertices, 0u);
  EXPECT_EQ(report.triangles, 0u);
  EXPECT_EQ(report.edges, 0u);
  EXPECT_EQ(report.components, 0u);
  EXPECT_EQ(report.euler_characteristic, 0);
  EXPECT_TRUE(report.orientable);
  EXPECT_EQ(report.used_vertex_fraction, 0.0);
  EXPECT_EQ(report.median_min_angle_deg, 0.0);
}

TEST(MeshQualityAngles, EquilateralAndRightIsosceles) {
  const Eigen::Vector3d origin(0, 0, 0), x(1, 0, 0), y(0, 1, 0);
  const Eigen::Vector3d apex(0.5, std::sqrt(3.0) / 2, 0);
  EXPECT_NEAR(minimumAngleDegrees(origin, x, apex), 60.0, 1e-12);
  EXPECT_NEAR(minimumAngleDegrees(origin, x, y), 45.0, 1e-12);
  EXPECT_EQ(minimumAngleDegrees(origin, x, Eigen::Vector3d(2, 0, 0)), 0.0);
  EXPECT_EQ(minimumAngleDegrees(origin, origin, x), 0.0);

  const MeshTopologyReport equilateral = analyzeMesh({origin, x, apex}, {{0, 1, 2}});
  EXPECT_NEAR(equilateral.median_min_angle_deg, 60.0, 1e-12);
  const MeshTopologyReport right = analyzeMesh({origin, x, y}, {{0, 1, 2}});
  EXPECT_NEAR(right.median_min_angle_deg, 45.0, 1e-12);
}

TEST(MeshQualityAngles, MedianAndShareOfSlivers) {
  // Equilateral (60), right isosceles (45) and a sliver (about 1.15 degrees).
  const std::vector<Eigen::Vector3d> vertices{{0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0},
                                              {0, 0, 1}, {1, 0, 1}, {0, 1, 1},
                                              {0, 0, 2}, {1, 0, 2}, {0.5, 0.01, 2}};
  const MeshTopologyReport report = analyzeMesh(vertices, {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}});
  EXPECT_NEAR(report.median_min_angle_deg, 45.0, 1e-12);
  EXPECT_NEAR(report.share_min_angle_below_10deg, 1.0 / 3.0, 1e-15);
}

// ---------------------------------------------------------------------------
// compareWithReference

TEST(MeshQualityReference, MeshAgainstItself) {
  const Mesh mesh = bumpyGrid(12);
  const ReferenceReport report = compare(mesh, mesh);
  EXPECT_EQ(report.reference_triangles, 288u);
  EXPECT_EQ(report.recovered_reference_triangles, 288u);
  EXPECT_EQ(report.recall, 1.0);
  EXPECT_EQ(report.precision, 1.0);
  EXPECT_LT(report.to_reference.max, 1e-12);
  EXPECT_LT(report.from_reference.max, 1e-12);
  EXPECT_LT(report.to_reference.mean, 1e-12);
  EXPECT_LT(report.from_reference.p95, 1e-12);
  EXPECT_EQ(report.fscore_0_1, 1.0);
  EXPECT_EQ(report.fscore_0_5, 1.0);
}

TEST(MeshQualityReference, SameSurfaceOtherTriangulation) {
  // Every quad split along its other diagonal: the vertices match but no
  // triangle does, so every distance goes through the AABB trees.
  const Mesh reference = flatGrid(8);
  Mesh ours = reference;
  for (std::size_t t = 0; t < ours.triangles.size(); t += 2) {
    const VertexIndex a = reference.triangles[t][0], b = reference.triangles[t][1],
                      c = reference.triangles[t][2], d = reference.triangles[t + 1][2];
    ours.triangles[t] = {a, b, d};
    ours.triangles[t + 1] = {b, c, d};
  }
  const ReferenceReport report = compare(ours, reference);
  EXPECT_EQ(report.recall, 0.0);
  EXPECT_EQ(report.precision, 0.0);
  EXPECT_LT(report.to_reference.max, 1e-12);
  EXPECT_LT(report.from_reference.max, 1e-12);
  EXPECT_EQ(report.fscore_0_1, 1.0);
  EXPECT_EQ(report.fscore_0_5, 1.0);
}

TEST(MeshQualityReference, MatchingIgnoresVertexAndCornerOrder) {
  const Mesh reference = cube();
  Mesh ours;
  // Vertices in reverse order, triangles reversed and rotated.
  const auto count = static_cast<VertexIndex>(reference.vertices.size());
  ours.vertices.assign(reference.vertices.rbegin(), reference.vertices.rend());
  for (auto it = reference.triangles.rbegin(); it != reference.triangles.rend(); ++it)
    ours.triangles.push_back({count - 1 - (*it)[1], count - 1 - (*it)[2], count - 1 - (*it)[0]});
  const ReferenceReport report = compare(ours, reference);
  EXPECT_EQ(report.recall, 1.0);
  EXPECT_EQ(report.precision, 1.0);
  EXPECT_NEAR(report.reference_diagonal, std::sqrt(3.0), 1e-15);
}

TEST(MeshQualityReference, DoubleReferenceMatchesTheFloatsMeshedFromIt) {
  // A reference read from text holds doubles (1/12 is no float); the cloud
  // meshed from it, and so the mesh, holds their float roundings.
  const Mesh reference = bumpyGrid(12);
  Mesh ours = reference;
  for (Eigen::Vector3d &vertex : ours.vertices)
    vertex = vertex.cast<float>().cast<double>();
  ASSERT_NE(ours.vertices[1], reference.vertices[1]);
  const ReferenceReport report = compare(ours, reference);
  EXPECT_EQ(report.recall, 1.0);
  EXPECT_EQ(report.precision, 1.0);
}

TEST(MeshQualityReference, PositionsThatRoundingWouldMergeAreComparedBitForBit) {
  // Floats lie 8 apart at 1e8: rounded, vertices 0 and 1 would be one
  // position, and our triangle on vertex 1 would pass for the reference's
  // on vertex 0.
  Mesh reference;
  reference.vertices = {
      {1e8, 0, 0}, {1e8 + 1, 0, 0}, {1e8, 100, 0}, {1e8 + 100, 0, 0}, {1e8 + 50, -100, 0}};
  reference.triangles = {{0, 3, 2}, {1, 4, 3}};
  Mesh ours = reference;
  ours.triangles = {{1, 3, 2}, {1, 4, 3}};
  const ReferenceReport report = compare(ours, reference);
  EXPECT_EQ(report.recovered_reference_triangles, 1u);
  EXPECT_EQ(report.recall, 0.5);
  EXPECT_EQ(report.precision, 0.5);
}

TEST(MeshQualityReference, ShiftAlongTheNormal) {
  const Mesh reference = flatGrid(10);
  const double diagonal = std::sqrt(2.0);
  const double shift = 0.003 * diagonal; // between the two F-score thresholds
  Mesh ours = reference;
  for (Eigen::Vector3d &vertex : ours.vertices)
    vertex.z() += shift;

  const ReferenceReport report = compare(ours, reference);
  EXPECT_NEAR(report.reference_diagonal, diagonal, 1e-15);
  for (const DistanceStats &stats : {report.to_reference, report.from_reference}) {
    EXPECT_NEAR(stats.mean, 0.003, 1e-12);
    EXPECT_NEAR(stats.p95, 0.003, 1e-12);
    EXPECT_NEAR(stats.max, 0.003, 1e-12);
  }
  EXPECT_EQ(report.fscore_0_1, 0.0);
  EXPECT_EQ(report.fscore_0_5, 1.0);
  // Exact matching sees no vertex in common...
  EXPECT_EQ(report.recall, 0.0);
  EXPECT_EQ(report.precision, 0.0);

  // ...matching within a tolerance larger than the shift sees them all,
  ReferenceOptions tolerant;
  tolerant.surface_samples = 0; // only matching is checked below
  tolerant.position_tolerance = 1.5 * shift;
  const ReferenceReport matched = compare(ours, reference, tolerant);
  EXPECT_EQ(matched.recall, 1.0);
  EXPECT_EQ(matched.precision, 1.0);

  // ...and one smaller than the shift none.
  ReferenceOptions strict = tolerant;
  strict.position_tolerance = 0.5 * shift;
  EXPECT_EQ(compare(ours, reference, strict).recall, 0.0);
}

TEST(MeshQualityReference, HalfTheTrianglesRemoved) {
  const Mesh reference = flatGrid(10);
  Mesh ours = reference;
  ours.triangles.resize(reference.triangles.size() / 2); // rows with y <= 0.5
  const double diagonal = std::sqrt(2.0);

  const ReferenceReport report = compare(ours, reference);
  EXPECT_EQ(report.recall, 0.5);
  EXPECT_EQ(report.precision, 1.0);
  EXPECT_EQ(report.recovered_reference_triangles, 100u);
  EXPECT_EQ(report.triangles_in_reference, 100u);
  EXPECT_LT(report.to_reference.max, 1e-12);
  // The far edge y = 1 lies 0.5 from what is left; its vertices are samples.
  EXPECT_NEAR(report.from_reference.max, 0.5 / diagonal, 1e-12);
  // Area-uniform: half the distances are 0, half uniform on [0, 0.5].
  EXPECT_NEAR(report.from_reference.mean, 0.125 / diagonal, 0.002);
  EXPECT_NEAR(report.from_reference.p95, 0.45 / diagonal, 0.003);
  // Precision 1, recall = 0.5 + tau (in units of the side) for the F-scores.
  const auto expected_fscore = [diagonal](double tau) {
    const double recall = 0.5 + tau * diagonal;
    return 2 * recall / (1 + recall);
  };
  EXPECT_NEAR(report.fscore_0_1, expected_fscore(0.001), 0.005);
  EXPECT_NEAR(report.fscore_0_5, expected_fscore(0.005), 0.005);
  EXPECT_LT(report.fscore_0_1, report.fscore_0_5);
}

TEST(MeshQualityReference, EdgeMidpointsCatchABridgingTriangle) {
  // Reference: floor z = 0 and wall x = 1 of the unit cube, each with its own
  // copy of the shared vertices (matching is by position, not index).
  const Mesh reference{{{0, 0, 0},
                        {1, 0, 0},
                        {1, 1, 0},
                        {0, 1, 0}, // floor
                        {1, 0, 0},
                        {1, 1, 0},
                        {1, 1, 1},
                        {1, 0, 1}}, // wall
                       {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}}};
  // Ours: the same surface on shared vertices plus a triangle cutting the
  // corner, whose farthest points (0.5 from both planes) are edge midpoints.
  const Mesh ours{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {1, 1, 1}, {1, 0, 1}},
                  {{0, 1, 2}, {0, 2, 3}, {1, 2, 4}, {1, 4, 5}, {0, 5, 3}}};
  ReferenceOptions no_random;
  no_random.surface_samples = 0;
  const ReferenceReport report = compare(ours, reference, no_random);
  EXPECT_EQ(report.recall, 1.0);
  EXPECT_EQ(report.precision, 0.8);
  EXPECT_NEAR(report.to_reference.max, 0.5 / std::sqrt(3.0), 1e-12);
  EXPECT_LT(report.from_reference.max, 1e-12);
}

TEST(MeshQualityReference, CollinearReferenceTriangleCountsAsItsSegment) {
  // The collinear triangle is listed right to left, so only its longest edge
  // 2-0 covers the whole segment from x = 0 to x = 2.
  const Mesh reference{{{2, 0, 0}, {1, 0, 0}, {0, 0, 0}, {0, 0, 5}, {1, 0, 5}, {0, 1, 5}},
                       {{0, 1, 2}, {3, 4, 5}}};
  EXPECT_EQ(analyze(reference).degenerate_triangles, 1u);
  const Mesh ours{{{1.5, 0.1, 0}, {1.6, 0.1, 0}, {1.5, 0.1, 0.1}}, {{0, 1, 2}}};
  const ReferenceReport report = compare(ours, reference);
  const double diagonal = std::sqrt(30.0); // box [0,2] x [0,1] x [0,5]
  EXPECT_NEAR(report.reference_diagonal, diagonal, 1e-15);
  // Farthest point of ours from the x axis: (1.5, 0.1, 0.1).
  EXPECT_NEAR(report.to_reference.max, std::sqrt(0.02) / diagonal, 1e-12);
  EXPECT_GE(report.to_reference.mean, 0.1 / diagonal);
}

TEST(MeshQualityReference, EmptyMeshesDoNotCrash) {
  const Mesh mesh = cube();
  const Mesh empty;
  const double infinity = std::numeric_limits<double>::infinity();

  const ReferenceReport nothing_built = compare(empty, mesh);
  EXPECT_EQ(nothing_built.recall, 0.0);
  EXPECT_EQ(nothing_built.precision, 0.0);
  EXPECT_EQ(nothing_built.to_reference.max, infinity);
  EXPECT_EQ(nothing_built.from_reference.mean, infinity);
  EXPECT_EQ(nothing_built.fscore_0_1, 0.0);
  EXPECT_EQ(nothing_built.fscore_0_5, 0.0);

  const ReferenceReport no_reference = compare(mesh, empty);
  EXPECT_EQ(no_reference.recall, 0.0);
  EXPECT_EQ(no_reference.reference_diagonal, 0.0);
  EXPECT_EQ(no_reference.from_reference.p95, infinity);

  const ReferenceReport both = compare(empty, empty);
  EXPECT_EQ(both.recall, 0.0);
  EXPECT_EQ(both.to_reference.mean, infinity);

  // Out-of-range indices are ignored for matching and distances but still
  // count as our triangles.
  Mesh broken = mesh;
  broken.triangles.push_back({0, 1, 99});
  broken.triangles.push_back({0, 99, 98});
  const ReferenceReport partly = compare(broken, mesh);
  EXPECT_EQ(partly.recall, 1.0);
  EXPECT_EQ(partly.precision, 12.0 / 14.0);
  EXPECT_LT(partly.to_reference.max, 1e-12);
}

TEST(MeshQualityReference, DeterministicForAGivenSeed) {
  const Mesh reference = flatGrid(16);
  Mesh ours = reference;
  ours.triangles.resize(ours.triangles.size() * 3 / 4); // rows with y <= 0.75
  ReferenceOptions options;
  options.surface_samples = 20000;
  const ReferenceReport first = compare(ours, reference, options);
  const ReferenceReport second = compare(ours, reference, options);
  EXPECT_EQ(first.from_reference.mean, second.from_reference.mean);
  EXPECT_EQ(first.from_reference.p95, second.from_reference.p95);
  EXPECT_EQ(first.fscore_0_1, second.fscore_0_1);
  options.seed = 2;
  const ReferenceReport reseeded = compare(ours, reference, options);
  EXPECT_NE(first.from_reference.mean, reseeded.from_reference.mean);
  // The max is reached on the far edge y = 1, at vertices, whatever the seed.
  EXPECT_NEAR(first.from_reference.max, 0.25 / std::sqrt(2.0), 1e-12);
  EXPECT_EQ(first.from_reference.max, reseeded.from_reference.max);
}

TEST(MeshQualityReference, AreaWeightingIgnoresTessellationDensity) {
  // The missing top half is refined 4x more than the kept bottom half, so
  // per-sample statistics over vertices, centroids and midpoints overweight it.
  const Mesh coarse = flatGrid(10);
  Mesh reference = coarse;
  reference.triangles.resize(coarse.triangles.size() / 2);
  const Mesh fine = flatGrid(40);
  const auto offset = static_cast<VertexIndex>(reference.vertices.size());
  reference.vertices.insert(reference.vertices.end(), fine.vertices.begin(), fine.vertices.end());
  for (std::size_t t = fine.triangles.size() / 2; t < fine.triangles.size(); ++t)
    reference.triangles.push_back({fine.triangles[t][0] + offset, fine.triangles[t][1] + offset,
                                   fine.triangles[t][2] + offset});
  Mesh ours = coarse;
  ours.triangles.resize(coarse.triangles.size() / 2);

  // Few random samples, so that the ~5000 deterministic ones on the fine half
  // weigh in when they are allowed to.
  ReferenceOptions area_weighted;
  area_weighted.surface_samples = 2000;
  ReferenceOptions per_sample = area_weighted;
  per_sample.area_weighted_statistics = false;
  const double area_mean = compare(ours, reference, area_weighted).from_reference.mean;
  const double sample_mean = compare(ours, reference, per_sample).from_reference.mean;
  EXPECT_NEAR(area_mean, 0.125 / std::sqrt(2.0), 0.01);
  EXPECT_GT(sample_mean, area_mean + 0.03);
}

} // namespace
} // namespace pcl_ms
