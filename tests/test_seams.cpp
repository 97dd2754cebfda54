// SPDX-License-Identifier: GPL-3.0-or-later
// Non-manifold seams, opt-in (docs/algorithm.md, "Seams (opt-in)"): on three
// half-planes meeting on one line and two boxes sharing a face, every seam
// edge holds three triangles and no other edge more than two; on manifold
// surfaces (the bunny, a sphere) the option finds no seam; with the option
// off the output is that of the default parameters, 2-manifold.
#include "program_test.h"
#include "test_support.h"

#include <pcl_ms/medial_scaffold_reconstruction.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <utility>

namespace {

using namespace pcl_ms_test;
using pcl_ms::Triangle;
using pcl_ms::VertexIndex;

using Edge = std::pair<VertexIndex, VertexIndex>;

Edge edgeOf(VertexIndex a, VertexIndex b) { return {std::min(a, b), std::max(a, b)}; }

std::map<Edge, int> edgeCounts(const std::vector<Triangle> &triangles) {
  std::map<Edge, int> counts;
  for (const Triangle &triangle : triangles)
    for (int k = 0; k < 3; ++k)
      ++counts[edgeOf(triangle[k], triangle[(k + 1) % 3])];
  return counts;
}

/// A cloud and the edges where its sheets meet (consecutive points along the
/// seam lines), with how many sheets meet there.
struct SeamCloud {
  std::vector<float> xyz;
  std::set<Edge> seam;
};

void add(std::vector<float> &xyz, double x, double y, double z) {
  xyz.push_back(static_cast<float>(x));
  xyz.push_back(static_cast<float>(y));
  xyz.push_back(static_cast<float>(z));
}

/// Half-planes at 0, 120 and 240 degrees around the z axis, each a 1 x 2
/// rectangle on a jittered grid (26 x 53 points off the line); the 53 points
/// on the line (z jittered only) are shared. Seam: the 52 line segments.
SeamCloud threeHalfPlanes() {
  std::mt19937 random(14);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  const int along = 26, up = 52;
  const double h = 1.0 / along;
  SeamCloud cloud;
  for (int j = 0; j <= up; ++j)
    add(cloud.xyz, 0, 0, (j + (j > 0 && j < up ? jitter(random) : 0.0)) * 2.0 / up);
  for (int j = 0; j + 1 <= up; ++j)
    cloud.seam.insert(edgeOf(static_cast<VertexIndex>(j), static_cast<VertexIndex>(j + 1)));
  for (int sheet = 0; sheet < 3; ++sheet) {
    const double angle = sheet * 2.0 * M_PI / 3.0;
    for (int i = 1; i <= along; ++i)
      for (int j = 0; j <= up; ++j) {
        const double r = (i + (i < along ? jitter(random) : 0.0)) * h;
        const double z = (j + (j > 0 && j < up ? jitter(random) : 0.0)) * 2.0 / up;
        add(cloud.xyz, r * std::cos(angle), r * std::sin(angle), z);
      }
  }
  return cloud;
}

/// Unit cubes [0,1]^3 and [1,2]x[0,1]^2: the union's surface and the shared
/// face x = 1, on a jittered grid of step 1/20 (points stay on their faces;
/// edge points move along their edge only). Seam: the 80 segments of the
/// shared square's rim, where the shared face meets two flat continuations.
SeamCloud twoBoxes() {
  std::mt19937 random(14);
  std::uniform_real_distribution<double> jitter(-0.15, 0.15);
  const int n = 20;
  const double h = 1.0 / n;
  SeamCloud cloud;
  std::map<std::array<int, 3>, VertexIndex> index;
  for (int i = 0; i <= 2 * n; ++i)
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= n; ++k) {
        const bool on_x = i == 0 || i == n || i == 2 * n, on_y = j == 0 || j == n,
                   on_z = k == 0 || k == n;
        if (!on_x && !on_y && !on_z)
          continue;
        // A coordinate on a face plane stays; others move within the face.
        const bool edge_x = i == 0 || i == 2 * n; // ends of the union box
        const double x = (i + (on_x || edge_x ? 0.0 : jitter(random))) * h;
        const double y = (j + (on_y ? 0.0 : jitter(random))) * h;
        const double z = (k + (on_z ? 0.0 : jitter(random))) * h;
        index[{i, j, k}] = static_cast<VertexIndex>(cloud.xyz.size() / 3);
        add(cloud.xyz, x, y, z);
      }
  // The shared square's rim: i = n with j or k on 0 or n.
  for (int t = 0; t < n; ++t)
    for (int fixed : {0, n}) {
      cloud.seam.insert(edgeOf(index[{n, fixed, t}], index[{n, fixed, t + 1}]));
      cloud.seam.insert(edgeOf(index[{n, t, fixed}], index[{n, t + 1, fixed}]));
    }
  return cloud;
}

pcl_ms::Result run(const SeamCloud &cloud, bool seams) {
  pcl_ms::Parameters parameters;
  parameters.allow_non_manifold = seams;
  return pcl_ms::reconstruct(viewOf(cloud.xyz), parameters);
}

/// Every seam segment holds `sheets` triangles, no other edge more than two,
/// and the result lists exactly the seam edges (docs/algorithm.md, "Seams
/// (opt-in)").
void expectSeams(const SeamCloud &cloud, const pcl_ms::Result &result, int sheets,
                 const char *name) {
  const auto counts = edgeCounts(result.triangles);
  std::size_t seam_right = 0, other_non_manifold = 0;
  std::vector<std::array<VertexIndex, 2>> listed;
  for (const auto &[edge, count] : counts) {
    if (count >= 3)
      listed.push_back({edge.first, edge.second});
    if (cloud.seam.count(edge))
      seam_right += count == sheets;
    else
      other_non_manifold += count > 2;
  }
  std::printf("%s: %zu triangles, %zu components, %zu seam triangles, %zu of %zu seam edges "
              "with %d triangles, %zu other edges with more than 2\n",
              name, result.triangles.size(), result.numberOfComponents(), result.seam_triangles,
              seam_right, cloud.seam.size(), sheets, other_non_manifold);
  EXPECT_EQ(seam_right, cloud.seam.size());
  EXPECT_EQ(other_non_manifold, 0u);
  EXPECT_EQ(result.seam_edges, listed);
  EXPECT_EQ(result.seam_edges.size(), cloud.seam.size());
  // Each manifold sheet is oriented consistently.
  EXPECT_EQ(result.numberOfNonOrientableComponents(), 0u);
}

/// Without the option: a 2-manifold mesh, the same as the default's.
void expectManifoldDefault(const SeamCloud &cloud, const char *name) {
  const pcl_ms::Result off = run(cloud, false);
  const pcl_ms::Result defaults = pcl_ms::reconstruct(viewOf(cloud.xyz), pcl_ms::Parameters());
  EXPECT_EQ(off.triangles, defaults.triangles);
  const auto counts = edgeCounts(off.triangles);
  std::size_t non_manifold = 0, seam_covered = 0;
  for (const auto &[edge, count] : counts) {
    non_manifold += count > 2;
    seam_covered += cloud.seam.count(edge) > 0;
  }
  std::printf("%s (off): %zu triangles, %zu components, %zu of %zu seam edges in the mesh\n", name,
              off.triangles.size(), off.numberOfComponents(), seam_covered, cloud.seam.size());
  EXPECT_EQ(non_manifold, 0u);
  EXPECT_TRUE(off.seam_edges.empty());
  EXPECT_EQ(off.seam_triangles, 0u);
}

TEST(Seams, ThreeHalfPlanes) {
  const SeamCloud cloud = threeHalfPlanes();
  expectManifoldDefault(cloud, "three half-planes");
  expectSeams(cloud, run(cloud, true), 3, "three half-planes");
}

TEST(Seams, TwoBoxesSharingAFace) {
  const SeamCloud cloud = twoBoxes();
  expectManifoldDefault(cloud, "two boxes");
  expectSeams(cloud, run(cloud, true), 3, "two boxes");
}

/// On manifold surfaces the option finds no seam: no seam edge, no edge
/// with more than two triangles, and the output of the option off.
void expectNoFalseSeams(const std::vector<float> &xyz, const char *name) {
  pcl_ms::Parameters parameters;
  const pcl_ms::Result off = pcl_ms::reconstruct(viewOf(xyz), parameters);
  parameters.allow_non_manifold = true;
  const pcl_ms::Result on = pcl_ms::reconstruct(viewOf(xyz), parameters);
  std::size_t non_manifold = 0;
  for (const auto &[edge, count] : edgeCounts(on.triangles))
    non_manifold += count > 2;
  std::printf("%s: %zu triangles, %zu seam edges, %zu seam triangles\n", name, on.triangles.size(),
              on.seam_edges.size(), on.seam_triangles);
  EXPECT_TRUE(on.seam_edges.empty());
  EXPECT_EQ(on.seam_triangles, 0u);
  EXPECT_EQ(non_manifold, 0u);
  EXPECT_EQ(on.triangles, off.triangles);
}

TEST(Seams, NoFalseSeamsOnTheBunny) {
  const auto cloud = loadXYZ("bunny.pcd");
  std::vector<float> xyz;
  for (const auto &p : *cloud)
    xyz.insert(xyz.end(), {p.x, p.y, p.z});
  expectNoFalseSeams(xyz, "bunny");
}

TEST(Seams, NoFalseSeamsOnASphere) { expectNoFalseSeams(fibonacciSphere(4000), "sphere"); }

TEST(Seams, PclClassOption) {
  pcl::MedialScaffoldReconstruction<pcl::PointXYZ> reconstruction;
  EXPECT_FALSE(reconstruction.getAllowNonManifold());
  reconstruction.setAllowNonManifold(true);
  EXPECT_TRUE(reconstruction.getAllowNonManifold());
}

class AppSeams : public TempDirTest {};

/// The cloud as an .xyz file in the test's directory.
std::string writeXyz(const SeamCloud &cloud, const std::string &file) {
  std::string xyz;
  char line[96];
  for (std::size_t i = 0; i < cloud.xyz.size(); i += 3) {
    std::snprintf(line, sizeof line, "%.9g %.9g %.9g\n", cloud.xyz[i], cloud.xyz[i + 1],
                  cloud.xyz[i + 2]);
    xyz += line;
  }
  writeFile(file, xyz);
  return file;
}

TEST_F(AppSeams, NonManifoldOptionReportsSeams) {
  const std::string app = std::string(PCL_MS_BINARY_DIR) + "/pcl_ms_reconstruct";
  ASSERT_TRUE(fs::exists(app)) << app << " was not built";
  writeXyz(threeHalfPlanes(), path("planes.xyz"));
  const std::string files = quoted(path("planes.xyz")) + " " + quoted(path("out.ply"));
  ASSERT_EQ(runProgram(app, files), 0) << stderr_;
  EXPECT_FALSE(contains(stdout_, "seam edges")) << stdout_;
  ASSERT_EQ(runProgram(app, files + " -non_manifold"), 0) << stderr_;
  EXPECT_TRUE(contains(stdout_, "seam edges")) << stdout_;
  EXPECT_TRUE(contains(stdout_, "seam triangles")) << stdout_;
  ASSERT_EQ(runProgram(app, "-h"), 0);
  EXPECT_TRUE(contains(stdout_ + stderr_, "-non_manifold"));
}

/// pcl_ms_compare -non_manifold runs pcl_ms with seams: its table shows the
/// option and the 52 seam edges as non-manifold edges (drawn red).
TEST_F(AppSeams, CompareDrawsSeams) {
  const std::string app = std::string(PCL_MS_BINARY_DIR) + "/pcl_ms_compare";
  if (!fs::exists(app))
    GTEST_SKIP() << app << " was not built (no VTK)";
  writeXyz(threeHalfPlanes(), path("planes.xyz"));
  const std::string out = path("compare");
  ASSERT_EQ(runProgram(app, quoted(path("planes.xyz")) + " -methods pcl_ms -q -non_manifold -out " +
                                quoted(out)),
            0)
      << stderr_;
  const std::string table = readFile(out + "/results.md");
  EXPECT_TRUE(contains(table, "non-manifold seams allowed")) << table;
  EXPECT_TRUE(contains(table, "| non-manifold edges | 52 |")) << table;
  ASSERT_EQ(runProgram(app, "-h"), 0);
  EXPECT_TRUE(contains(stdout_ + stderr_, "-non_manifold"));
}

} // namespace
