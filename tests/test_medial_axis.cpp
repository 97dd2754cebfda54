// SPDX-License-Identifier: GPL-3.0-or-later
// The medial axis output (docs/algorithm.md, "Medial axis output"): a
// sampled sphere's and torus's nodes lie on their known medial axes, the
// feature changes nothing when off, and bad input is an error.
#include "program_test.h"
#include "test_support.h"

#include <pcl_ms/medial_axis.h>
#include <pcl_ms/medial_scaffold_reconstruction.h>

#include <algorithm>
#include <cstdio>
#include <random>

namespace {

using pcl_ms::MedialAxis;
using pcl_ms_test::viewOf;

/// A double in [0, 1) from the raw output of std::mt19937_64, which the
/// standard fixes (its distributions it does not).
double uniform(std::mt19937_64 &random) { return (random() >> 11) * 0x1.0p-53; }

/// `n` points uniformly random on a sphere (Archimedes: uniform height and
/// angle give uniform area).
std::vector<float> randomSphere(int n, double radius, const Eigen::Vector3d &centre,
                                std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::vector<float> xyz;
  for (int i = 0; i < n; ++i) {
    const double z = 2 * uniform(random) - 1, phi = 2 * M_PI * uniform(random);
    const double ring = std::sqrt(1 - z * z);
    const Eigen::Vector3d p =
        centre + radius * Eigen::Vector3d(ring * std::cos(phi), ring * std::sin(phi), z);
    xyz.insert(xyz.end(), {float(p.x()), float(p.y()), float(p.z())});
  }
  return xyz;
}

/// `n` points uniformly random by area on a torus around the z axis (the
/// tube angle is drawn with probability in proportion to the ring's length).
std::vector<float> randomTorus(int n, double major, double minor, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::vector<float> xyz;
  while (static_cast<int>(xyz.size()) < 3 * n) {
    const double theta = 2 * M_PI * uniform(random), phi = 2 * M_PI * uniform(random);
    if (uniform(random) * (major + minor) > major + minor * std::cos(phi))
      continue;
    const double ring = major + minor * std::cos(phi);
    xyz.insert(xyz.end(), {float(ring * std::cos(theta)), float(ring * std::sin(theta)),
                           float(minor * std::sin(phi))});
  }
  return xyz;
}

pcl_ms::Result reconstructWithAxis(const std::vector<float> &xyz) {
  pcl_ms::Parameters parameters;
  parameters.compute_medial_axis = true;
  return pcl_ms::reconstruct(viewOf(xyz), parameters);
}

std::size_t countSide(const MedialAxis &axis, MedialAxis::Side side) {
  return static_cast<std::size_t>(std::count(axis.node_side.begin(), axis.node_side.end(), side));
}

void expectConsistent(const MedialAxis &axis) {
  const std::size_t nodes = axis.node_positions.size();
  ASSERT_EQ(axis.node_radii.size(), nodes);
  ASSERT_EQ(axis.node_side.size(), nodes);
  for (const auto &curve : axis.curves) {
    EXPECT_LT(curve[0], curve[1]);
    EXPECT_LT(curve[1], nodes);
  }
  EXPECT_TRUE(std::is_sorted(axis.curves.begin(), axis.curves.end()));
}

TEST(MedialAxis, SphereNodesSitAtItsCentreWithItsRadius) {
  // Off the origin, so that the nodes must come back in the user's frame.
  const Eigen::Vector3d centre(3, -2, 5);
  const std::vector<float> xyz = randomSphere(5000, 1.0, centre, 20261130);
  const pcl_ms::Result result = reconstructWithAxis(xyz);
  ASSERT_TRUE(result.boundary_loops.empty()); // closed: it has an inside
  ASSERT_TRUE(result.medial_axis.has_value());
  const MedialAxis &axis = *result.medial_axis;
  expectConsistent(axis);
  // Every point is on the hull: its outer pole is at infinity, so every
  // node is an inner pole.
  ASSERT_GT(axis.node_positions.size(), 10u);
  EXPECT_EQ(countSide(axis, MedialAxis::inside), axis.node_positions.size());
  double worst_offset = 0, worst_radius_error = 0;
  for (std::size_t n = 0; n < axis.node_positions.size(); ++n) {
    worst_offset = std::max(worst_offset, (axis.node_positions[n] - centre).norm());
    worst_radius_error = std::max(worst_radius_error, std::abs(axis.node_radii[n] - 1.0));
  }
  std::printf("sphere: %zu nodes, %zu curves, farthest node %.3g from the centre, "
              "worst radius error %.3g\n",
              axis.node_positions.size(), axis.curves.size(), worst_offset, worst_radius_error);
  EXPECT_LT(worst_offset, 0.05);
  EXPECT_LT(worst_radius_error, 0.05);
}

TEST(MedialAxis, TorusInnerNodesSitOnItsCoreCircle) {
  constexpr double major = 1.0, minor = 0.3;
  const std::vector<float> xyz = randomTorus(20000, major, minor, 20261130);
  const pcl_ms::Result result = reconstructWithAxis(xyz);
  ASSERT_TRUE(result.boundary_loops.empty());
  ASSERT_TRUE(result.medial_axis.has_value());
  const MedialAxis &axis = *result.medial_axis;
  expectConsistent(axis);
  std::size_t inner = 0;
  double worst_offset = 0, worst_radius_error = 0;
  for (std::size_t n = 0; n < axis.node_positions.size(); ++n) {
    if (axis.node_side[n] != MedialAxis::inside)
      continue;
    ++inner;
    const Eigen::Vector3d &p = axis.node_positions[n];
    const double off_core = std::hypot(std::hypot(p.x(), p.y()) - major, p.z());
    worst_offset = std::max(worst_offset, off_core);
    worst_radius_error = std::max(worst_radius_error, std::abs(axis.node_radii[n] - minor));
  }
  std::printf("torus: %zu nodes (%zu inside, %zu outside), %zu curves, farthest inner node "
              "%.3g from the core circle, worst inner radius error %.3g\n",
              axis.node_positions.size(), inner, countSide(axis, MedialAxis::outside),
              axis.curves.size(), worst_offset, worst_radius_error);
  EXPECT_GT(inner, 1000u);
  EXPECT_LT(worst_offset, 0.05 * minor);
  EXPECT_LT(worst_radius_error, 0.05 * minor);
  EXPECT_EQ(countSide(axis, MedialAxis::open), 0u);
}

TEST(MedialAxis, NonDelaunayTrianglesStillWallOffTheInside) {
  // Swap the diagonals of quads of a sampled sphere's mesh: the new
  // triangles are not Delaunay facets (the sphere's are its hull), so the
  // walls have gaps that only the plugs close.
  const std::vector<float> xyz = randomSphere(3000, 1.0, Eigen::Vector3d::Zero(), 13);
  const pcl_ms::Result result = pcl_ms::reconstruct(viewOf(xyz), pcl_ms::Parameters());
  ASSERT_TRUE(result.boundary_loops.empty());
  std::vector<pcl_ms::Triangle> triangles = result.triangles;
  std::vector<bool> touched(xyz.size() / 3, false);
  std::size_t swapped = 0;
  for (std::size_t t = 0; t < triangles.size() && swapped < 20; ++t)
    for (std::size_t u = t + 1; u < triangles.size(); ++u) {
      // Shared edge (a, b), apexes c and d, all untouched so far.
      std::vector<pcl_ms::VertexIndex> shared, apexes;
      for (pcl_ms::VertexIndex v : triangles[t])
        (std::count(triangles[u].begin(), triangles[u].end(), v) ? shared : apexes).push_back(v);
      if (shared.size() != 2)
        continue;
      for (pcl_ms::VertexIndex v : triangles[u])
        if (!std::count(shared.begin(), shared.end(), v))
          apexes.push_back(v);
      if (touched[shared[0]] || touched[shared[1]] || touched[apexes[0]] || touched[apexes[1]])
        break;
      triangles[t] = {apexes[0], apexes[1], shared[0]};
      triangles[u] = {apexes[0], apexes[1], shared[1]};
      for (pcl_ms::VertexIndex v : {shared[0], shared[1], apexes[0], apexes[1]})
        touched[v] = true;
      ++swapped;
      break;
    }
  ASSERT_EQ(swapped, 20u);
  const MedialAxis axis = pcl_ms::computeMedialAxis(pcl_ms_test::positions(xyz), triangles);
  ASSERT_GT(axis.node_positions.size(), 10u);
  EXPECT_EQ(countSide(axis, MedialAxis::inside), axis.node_positions.size());
}

TEST(MedialAxis, OffByDefaultAndTheMeshIsTheSameEitherWay) {
  const std::vector<float> xyz = randomSphere(3000, 1.0, Eigen::Vector3d::Zero(), 7);
  EXPECT_FALSE(pcl_ms::Parameters().compute_medial_axis);
  const pcl_ms::Result off = pcl_ms::reconstruct(viewOf(xyz), pcl_ms::Parameters());
  EXPECT_FALSE(off.medial_axis.has_value());
  EXPECT_EQ(off.timings.medial_axis, 0.0);
  const pcl_ms::Result on = reconstructWithAxis(xyz);
  ASSERT_TRUE(on.medial_axis.has_value());
  EXPECT_EQ(on.triangles, off.triangles);
  EXPECT_EQ(on.boundary_loops, off.boundary_loops);
}

void expectSameAxis(const MedialAxis &actual, const MedialAxis &expected) {
  EXPECT_EQ(actual.node_positions, expected.node_positions);
  EXPECT_EQ(actual.node_radii, expected.node_radii);
  EXPECT_EQ(actual.node_side, expected.node_side);
  EXPECT_EQ(actual.curves, expected.curves);
}

TEST(MedialAxis, SameAxisWhateverThePointOrder) {
  const std::vector<float> xyz = randomTorus(4000, 1.0, 0.3, 11);
  const pcl_ms::Result result = pcl_ms::reconstruct(viewOf(xyz), pcl_ms::Parameters());
  std::vector<Eigen::Vector3d> points = pcl_ms_test::positions(xyz);
  const MedialAxis axis = pcl_ms::computeMedialAxis(points, result.triangles);

  // Reverse the points and renumber the triangles to match.
  const auto count = static_cast<pcl_ms::VertexIndex>(points.size());
  std::reverse(points.begin(), points.end());
  std::vector<pcl_ms::Triangle> renumbered = result.triangles;
  for (pcl_ms::Triangle &triangle : renumbered)
    for (pcl_ms::VertexIndex &v : triangle)
      v = count - 1 - v;
  const MedialAxis reversed = pcl_ms::computeMedialAxis(points, renumbered);
  EXPECT_GT(axis.node_positions.size(), 0u);
  expectSameAxis(reversed, axis);
}

TEST(MedialAxis, SameFromReconstructWhateverTheOrderAndThreads) {
  const std::vector<float> xyz = randomTorus(3000, 1.0, 0.3, 19);
  std::vector<float> reversed;
  for (std::size_t i = xyz.size(); i >= 3; i -= 3)
    reversed.insert(reversed.end(), {xyz[i - 3], xyz[i - 2], xyz[i - 1]});
  pcl_ms::Parameters parameters;
  parameters.compute_medial_axis = true;
  const MedialAxis one = *pcl_ms::reconstruct(viewOf(xyz), parameters).medial_axis;
  parameters.num_threads = 2;
  parameters.min_points_for_threads = 0; // threads, however few the points
  const MedialAxis other = *pcl_ms::reconstruct(viewOf(reversed), parameters).medial_axis;
  EXPECT_GT(one.node_positions.size(), 0u);
  expectSameAxis(other, one);
}

TEST(MedialAxis, OpenSurfaceGivesNoInside) {
  // A hemisphere: everything is reachable from outside past its rim.
  std::vector<float> xyz = randomSphere(3000, 1.0, Eigen::Vector3d::Zero(), 5), upper;
  for (std::size_t i = 0; i < xyz.size(); i += 3)
    if (xyz[i + 2] > 0)
      upper.insert(upper.end(), {xyz[i], xyz[i + 1], xyz[i + 2]});
  const pcl_ms::Result result = reconstructWithAxis(upper);
  ASSERT_FALSE(result.boundary_loops.empty());
  const MedialAxis &axis = *result.medial_axis;
  expectConsistent(axis);
  EXPECT_GT(axis.node_positions.size(), 0u);
  EXPECT_EQ(countSide(axis, MedialAxis::inside), 0u);
  EXPECT_EQ(countSide(axis, MedialAxis::outside), 0u);
}

TEST(MedialAxis, BadInputIsAnErrorNotACrash) {
  std::vector<Eigen::Vector3d> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  // Too few points, or all on one plane: no tetrahedra, no nodes.
  EXPECT_TRUE(pcl_ms::computeMedialAxis({}, {}).node_positions.empty());
  EXPECT_TRUE(pcl_ms::computeMedialAxis({points.begin(), points.begin() + 3}, {{0, 1, 2}})
                  .node_positions.empty());
  EXPECT_TRUE(pcl_ms::computeMedialAxis({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 3, 0}}, {})
                  .node_positions.empty());
  // Duplicates stand for one point, also in the triangles.
  std::vector<Eigen::Vector3d> doubled = points;
  doubled.push_back(points[1]);
  const MedialAxis with_duplicate = pcl_ms::computeMedialAxis(doubled, {{0, 5, 2}});
  expectConsistent(with_duplicate);
  EXPECT_EQ(with_duplicate.node_positions, pcl_ms::computeMedialAxis(points, {}).node_positions);
  // A triangle outside the points, or a non-finite point, is an error.
  EXPECT_THROW(pcl_ms::computeMedialAxis(points, {{0, 1, 5}}), pcl_ms::ReconstructionError);
  points[2].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(pcl_ms::computeMedialAxis(points, {}), pcl_ms::ReconstructionError);
}

TEST(MedialAxis, PclClassReturnsItOnlyWhenAsked) {
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  const std::vector<float> xyz = randomSphere(2000, 2.0, Eigen::Vector3d(1, 1, 1), 3);
  for (std::size_t i = 0; i < xyz.size(); i += 3)
    cloud->push_back(pcl::PointXYZ(xyz[i], xyz[i + 1], xyz[i + 2]));
  pcl::MedialScaffoldReconstruction<pcl::PointXYZ> reconstruction;
  reconstruction.setInputCloud(cloud);
  pcl::PolygonMesh mesh;
  reconstruction.reconstruct(mesh);
  EXPECT_FALSE(reconstruction.getComputeMedialAxis());
  EXPECT_TRUE(reconstruction.getMedialScaffold().node_positions.empty());
  reconstruction.setComputeMedialAxis(true);
  reconstruction.reconstruct(mesh);
  const MedialAxis &axis = reconstruction.getMedialScaffold();
  ASSERT_GT(axis.node_positions.size(), 0u);
  for (std::size_t n = 0; n < axis.node_positions.size(); ++n) {
    EXPECT_LT((axis.node_positions[n] - Eigen::Vector3d(1, 1, 1)).norm(), 0.1);
    EXPECT_NEAR(axis.node_radii[n], 2.0, 0.1);
  }
}

class MedialAxisTool : public pcl_ms_test::TempDirTest {
protected:
  std::string tool() const { return std::string(PCL_MS_BINARY_DIR) + "/pcl_ms_reconstruct"; }
};

TEST_F(MedialAxisTool, WritesNodesWithRadiusAndCurvesAsEdges) {
  const std::vector<float> xyz = randomSphere(2000, 1.0, Eigen::Vector3d::Zero(), 9);
  std::string text;
  for (std::size_t i = 0; i < xyz.size(); i += 3)
    text += std::to_string(xyz[i]) + " " + std::to_string(xyz[i + 1]) + " " +
            std::to_string(xyz[i + 2]) + "\n";
  pcl_ms_test::writeFile(path("sphere.xyz"), text);
  ASSERT_EQ(runProgram(tool(), pcl_ms_test::quoted(path("sphere.xyz")) + " " +
                                   pcl_ms_test::quoted(path("mesh.ply")) + " -medial_axis " +
                                   pcl_ms_test::quoted(path("axis.ply"))),
            0)
      << stderr_;
  EXPECT_TRUE(pcl_ms_test::contains(stdout_, "medial axis"));
  const std::string ply = pcl_ms_test::readFile(path("axis.ply"));
  const std::size_t body = ply.find("end_header\n");
  ASSERT_NE(body, std::string::npos);
  const std::string header = ply.substr(0, body);
  EXPECT_TRUE(pcl_ms_test::contains(header, "property float radius\n"));
  EXPECT_TRUE(pcl_ms_test::contains(header, "property uchar inside\n"));
  EXPECT_TRUE(pcl_ms_test::contains(header, "property int vertex1\nproperty int vertex2\n"));
  unsigned long nodes = 0, curves = 0;
  ASSERT_EQ(
      std::sscanf(header.c_str() + header.find("element vertex"), "element vertex %lu", &nodes), 1);
  ASSERT_EQ(std::sscanf(header.c_str() + header.find("element edge"), "element edge %lu", &curves),
            1);
  EXPECT_GT(nodes, 0u);
  // Binary: 4 floats and a byte per node, two ints per curve.
  EXPECT_EQ(ply.size() - body - std::string("end_header\n").size(), nodes * 17 + curves * 8);

  // Only .ply, and no file when not asked for.
  EXPECT_EQ(runProgram(tool(), pcl_ms_test::quoted(path("sphere.xyz")) + " " +
                                   pcl_ms_test::quoted(path("mesh2.ply")) + " -medial_axis " +
                                   pcl_ms_test::quoted(path("axis.obj"))),
            1);
  EXPECT_TRUE(pcl_ms_test::contains(stderr_, ".ply only")) << stderr_;
  EXPECT_FALSE(pcl_ms_test::fs::exists(path("mesh2.ply")));
  EXPECT_EQ(runProgram(tool(), pcl_ms_test::quoted(path("sphere.xyz")) + " " +
                                   pcl_ms_test::quoted(path("mesh3.ply")) + " -medial_axis"),
            1);
  EXPECT_EQ(runProgram(tool(), pcl_ms_test::quoted(path("sphere.xyz")) + " " +
                                   pcl_ms_test::quoted(path("mesh4.ply")) + " -medial_axis " +
                                   pcl_ms_test::quoted(path("missing/axis.ply"))),
            2);
  EXPECT_TRUE(pcl_ms_test::contains(stderr_, "does not exist")) << stderr_;
  EXPECT_FALSE(pcl_ms_test::fs::exists(path("mesh4.ply")));
}

TEST_F(MedialAxisTool, CompareDrawsItBesideTheSurface) {
  const std::vector<float> xyz = randomTorus(4000, 1.0, 0.3, 17);
  std::string text;
  for (std::size_t i = 0; i < xyz.size(); i += 3)
    text += std::to_string(xyz[i]) + " " + std::to_string(xyz[i + 1]) + " " +
            std::to_string(xyz[i + 2]) + "\n";
  pcl_ms_test::writeFile(path("torus.xyz"), text);
  const std::string compare = std::string(PCL_MS_BINARY_DIR) + "/pcl_ms_compare";
  const std::string common = pcl_ms_test::quoted(path("torus.xyz")) +
                             " -methods pcl_ms -picture_size 200 -q -out " +
                             pcl_ms_test::quoted(path("out"));
  ASSERT_EQ(runProgram(compare, common + " -medial_axis"), 0) << stderr_;
  const std::string ply = pcl_ms_test::readFile(path("out/medial_axis.ply"));
  EXPECT_TRUE(
      pcl_ms_test::contains(ply.substr(0, ply.find("end_header")), "property float radius"));
  // The renderer is required, as in the Render tests.
  EXPECT_FALSE(pcl_ms_test::contains(stderr_, "not written")) << stderr_;
  EXPECT_EQ(pcl_ms_test::readFile(path("out/medial_axis.png")).substr(0, 8), "\x89PNG\r\n\x1a\n");
  // Without the option, an earlier run's medial axis files go.
  ASSERT_EQ(runProgram(compare, common), 0) << stderr_;
  EXPECT_FALSE(pcl_ms_test::fs::exists(path("out/medial_axis.ply")));
  EXPECT_FALSE(pcl_ms_test::fs::exists(path("out/medial_axis.png")));
}

} // namespace
