// SPDX-License-Identifier: GPL-3.0-or-later
// Initial triangles in preferred mode (docs/algorithm.md, "Initial
// triangles"): a polygon soup of a real mesh with 10 % of its triangles
// wrong comes out a clean manifold mesh; fixed mode rejects the same soup.
#include "program_test.h"
#include "test_support.h"

#include <pcl_ms/medial_scaffold_reconstruction.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <random>
#include <set>

namespace {

using namespace pcl_ms_test;
using pcl_ms::InitialTrianglesMode;
using pcl_ms::Triangle;

Triangle sorted(Triangle triangle) {
  std::sort(triangle.begin(), triangle.end());
  return triangle;
}

std::set<Triangle> sortedSet(const std::vector<Triangle> &triangles) {
  std::set<Triangle> set;
  for (const Triangle &triangle : triangles)
    set.insert(sorted(triangle));
  return set;
}

std::size_t countIn(const std::set<Triangle> &set, const std::vector<Triangle> &triangles) {
  std::size_t count = 0;
  for (const Triangle &triangle : triangles)
    count += set.count(sorted(triangle));
  return count;
}

/// The bunny mesh (bun_zipper.ply, whose vertices are bunny.pcd) with 10 %
/// of its triangles replaced by wrong ones: 60 % of those join three
/// vertices far apart (they cross the surface), 20 % overlap two right
/// triangles (the other diagonal of their quad) and 20 % repeat a right
/// triangle with its corners in another order.
struct Soup {
  std::vector<Triangle> triangles;
  std::vector<Triangle> right;       // the original triangles kept in the soup
  std::vector<Triangle> crossing;    // wrong: far-apart corners
  std::vector<Triangle> overlapping; // wrong: the other diagonal of a quad
  std::size_t repeats = 0;
};

Soup makeSoup(const ReferenceMesh &mesh) {
  std::mt19937 random(14);
  const std::size_t count = mesh.triangles.size();
  std::vector<std::size_t> order(count);
  for (std::size_t i = 0; i < count; ++i)
    order[i] = i;
  std::shuffle(order.begin(), order.end(), random);
  const std::size_t wrong_count = count / 10;
  std::vector<bool> replaced(count, false);
  for (std::size_t i = 0; i < wrong_count; ++i)
    replaced[order[i]] = true;

  Soup soup;
  for (std::size_t t = 0; t < count; ++t)
    if (!replaced[t])
      soup.right.push_back(mesh.triangles[t]);
  // Triangles on each edge of the right ones, for the overlapping kind.
  std::map<std::pair<pcl_ms::VertexIndex, pcl_ms::VertexIndex>, std::vector<std::size_t>> on_edge;
  for (std::size_t t = 0; t < soup.right.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      pcl_ms::VertexIndex a = soup.right[t][k], b = soup.right[t][(k + 1) % 3];
      on_edge[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  std::vector<pcl_ms::VertexIndex> used;
  for (const Triangle &triangle : mesh.triangles)
    used.insert(used.end(), triangle.begin(), triangle.end());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  Eigen::Vector3d low = mesh.vertices[used[0]], high = low;
  for (pcl_ms::VertexIndex v : used) {
    low = low.cwiseMin(mesh.vertices[v]);
    high = high.cwiseMax(mesh.vertices[v]);
  }
  const double far = 0.1 * (high - low).norm();
  std::uniform_int_distribution<std::size_t> any_vertex(0, used.size() - 1);
  std::uniform_int_distribution<std::size_t> any_right(0, soup.right.size() - 1);

  soup.triangles = mesh.triangles;
  for (std::size_t i = 0; i < wrong_count; ++i) {
    Triangle &slot = soup.triangles[order[i]];
    const std::size_t kind = i % 10;
    if (kind < 6) {
      Triangle triangle;
      do {
        triangle = {used[any_vertex(random)], used[any_vertex(random)], used[any_vertex(random)]};
      } while ((mesh.vertices[triangle[0]] - mesh.vertices[triangle[1]]).norm() < far ||
               (mesh.vertices[triangle[1]] - mesh.vertices[triangle[2]]).norm() < far ||
               (mesh.vertices[triangle[2]] - mesh.vertices[triangle[0]]).norm() < far);
      slot = triangle;
      soup.crossing.push_back(triangle);
    } else if (kind < 8) {
      // Right triangles (a, b, c) and (a, c, d) across edge ac: (a, b, d)
      // overlaps both.
      for (;;) {
        const Triangle &first = soup.right[any_right(random)];
        const pcl_ms::VertexIndex a = first[0], b = first[1], c = first[2];
        const auto &across = on_edge[{std::min(a, c), std::max(a, c)}];
        if (across.size() != 2)
          continue;
        const Triangle &second =
            soup.right[across[0]] == first ? soup.right[across[1]] : soup.right[across[0]];
        pcl_ms::VertexIndex d = second[0];
        for (pcl_ms::VertexIndex v : second)
          if (v != a && v != c)
            d = v;
        slot = {a, b, d};
        soup.overlapping.push_back(slot);
        break;
      }
    } else {
      const Triangle &copy = soup.right[any_right(random)];
      slot = {copy[2], copy[1], copy[0]};
      ++soup.repeats;
    }
  }
  return soup;
}

double seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace

TEST(InitialTrianglesSoup, PreferredModeCleansABunnySoupWithTenPercentWrong) {
  const ReferenceMesh &mesh = bunnyReference();
  const auto cloud = loadXYZ("bunny.pcd");
  ASSERT_EQ(cloud->size(), mesh.vertices.size());
  const Soup soup = makeSoup(mesh);
  ASSERT_EQ(soup.triangles.size(), mesh.triangles.size());

  auto start = std::chrono::steady_clock::now();
  const pcl_ms::Result plain = pcl_ms::reconstruct(viewOf(*cloud), pcl_ms::Parameters());
  const double plain_seconds = seconds(start);

  pcl_ms::Parameters parameters;
  parameters.initial_triangles_mode = InitialTrianglesMode::preferred;
  start = std::chrono::steady_clock::now();
  const pcl_ms::Result result = pcl_ms::reconstruct(viewOf(*cloud), parameters, soup.triangles);
  const double preferred_seconds = seconds(start);

  const pcl_ms::MeshTopologyReport report =
      pcl_ms::analyzeMesh(positions(*cloud), result.triangles);
  expectCleanManifold(report);

  const std::set<Triangle> output = sortedSet(result.triangles);
  const std::set<Triangle> original = sortedSet(mesh.triangles);
  const std::size_t right_kept = countIn(output, soup.right);
  const std::size_t crossing_kept = countIn(output, soup.crossing);
  const std::size_t overlapping_kept = countIn(output, soup.overlapping);
  const std::size_t correct = countIn(original, result.triangles);
  const std::size_t plain_correct = countIn(original, plain.triangles);
  std::printf("soup: %zu triangles, %zu right, %zu crossing, %zu overlapping, %zu repeats\n",
              soup.triangles.size(), soup.right.size(), soup.crossing.size(),
              soup.overlapping.size(), soup.repeats);
  std::printf("preferred: %zu triangles; right kept %zu (%.2f %%), crossing kept %zu, "
              "overlapping kept %zu; repeats merged %zu, invalid %zu, oversize %zu\n",
              result.triangles.size(), right_kept, 100.0 * right_kept / soup.right.size(),
              crossing_kept, overlapping_kept, result.initial_duplicates, result.initial_invalid,
              result.initial_oversize);
  std::printf("against the original mesh: precision %.2f %%, recall %.2f %% (plain "
              "reconstruction: %.2f %%, %.2f %%)\n",
              100.0 * correct / result.triangles.size(), 100.0 * correct / mesh.triangles.size(),
              100.0 * plain_correct / plain.triangles.size(),
              100.0 * plain_correct / mesh.triangles.size());
  std::printf("time: preferred %.2f s, plain %.2f s; %zu boundary loops (plain %zu), %zu "
              "components\n",
              preferred_seconds, plain_seconds, result.boundary_loops.size(),
              plain.boundary_loops.size(), result.numberOfComponents());

  EXPECT_GE(static_cast<double>(right_kept), 0.99 * soup.right.size());
  EXPECT_EQ(crossing_kept, 0u);
  // Overlapping ones come after the right ones they overlap and lose (1
  // of 1,388 kept, measured, and that one is also a triangle of the mesh).
  EXPECT_LE(overlapping_kept, soup.overlapping.size() / 100);
  // The repeats, and the few wrong triangles that happen to be another one.
  EXPECT_EQ(result.initial_duplicates, soup.triangles.size() - sortedSet(soup.triangles).size());
  EXPECT_GE(result.initial_duplicates, soup.repeats);
  EXPECT_EQ(result.initial_kept, countIn(sortedSet(soup.triangles), result.triangles));
  // The replaced triangles' places are filled: the mesh is closer to the
  // original than the soup's right part alone.
  EXPECT_GT(correct, right_kept);

  // Fixed mode rejects the same soup with the reason.
  try {
    pcl_ms::reconstruct(viewOf(*cloud), pcl_ms::Parameters(), soup.triangles);
    ADD_FAILURE() << "fixed mode accepted the soup";
  } catch (const pcl_ms::ReconstructionError &error) {
    EXPECT_TRUE(contains(error.what(), "twice") || contains(error.what(), "more than two"))
        << error.what();
  }
}

TEST(InitialTrianglesSoup, PreferredModeMergesRepeatsAndLeavesOutInvalidOnes) {
  const std::vector<float> xyz = fibonacciSphere(400);
  const pcl_ms::Result plain = pcl_ms::reconstruct(viewOf(xyz), pcl_ms::Parameters());
  ASSERT_GT(plain.triangles.size(), 100u);
  std::vector<Triangle> soup(plain.triangles.begin(), plain.triangles.begin() + 100);
  const Triangle first = soup[0];
  soup.push_back({first[1], first[2], first[0]}); // repeated
  soup.push_back({first[2], first[1], first[0]}); // repeated, other orientation
  soup.push_back({0, 1, 400});                    // no such point
  soup.push_back({5, 5, 6});                      // one point twice
  soup.push_back({0, 100, 200});                  // far apart: oversize
  pcl_ms::Parameters parameters;
  parameters.initial_triangles_mode = InitialTrianglesMode::preferred;
  const pcl_ms::Result result = pcl_ms::reconstruct(viewOf(xyz), parameters, soup);
  EXPECT_EQ(result.initial_duplicates, 2u);
  EXPECT_EQ(result.initial_invalid, 2u);
  EXPECT_EQ(result.initial_oversize, 1u);
  EXPECT_EQ(result.initial_kept, 100u);
  expectCleanManifold(pcl_ms::analyzeMesh(positions(xyz), result.triangles));
  EXPECT_EQ(result.boundary_loops.size(), 0u);
  // A soup of right triangles changes nothing on a clean sphere.
  const std::set<Triangle> expected = sortedSet(plain.triangles);
  EXPECT_EQ(sortedSet(result.triangles), expected);
}

TEST(InitialTrianglesSoup, PclClassSetsTheMode) {
  const auto cloud = loadXYZ("bun0.pcd");
  using Reconstruction = pcl::MedialScaffoldReconstruction<pcl::PointXYZ>;
  Reconstruction reconstruction;
  EXPECT_EQ(reconstruction.getInitialTrianglesMode(), Reconstruction::InitialTrianglesMode::fixed);
  reconstruction.setInputCloud(cloud);
  std::vector<pcl::Vertices> polygons;
  reconstruction.reconstruct(*cloud, polygons);
  ASSERT_GT(polygons.size(), 100u);

  std::vector<pcl::Vertices> soup(polygons.begin(), polygons.begin() + 50);
  soup.push_back(soup[0]); // repeated: fixed mode rejects it
  pcl::Vertices quad;
  quad.vertices = {0, 1, 2, 3};
  soup.push_back(quad);
  reconstruction.setInitialTriangles(soup);
  std::vector<pcl::Vertices> completed;
  reconstruction.reconstruct(*cloud, completed);
  EXPECT_TRUE(completed.empty());
  EXPECT_FALSE(reconstruction.getErrorMessage().empty());

  reconstruction.setInitialTrianglesMode(Reconstruction::InitialTrianglesMode::preferred);
  EXPECT_EQ(reconstruction.getInitialTrianglesMode(),
            Reconstruction::InitialTrianglesMode::preferred);
  reconstruction.reconstruct(*cloud, completed);
  EXPECT_TRUE(reconstruction.getErrorMessage().empty()) << reconstruction.getErrorMessage();
  EXPECT_EQ(reconstruction.getResult().initial_duplicates, 1u);
  EXPECT_EQ(reconstruction.getResult().initial_invalid, 1u);
  EXPECT_EQ(reconstruction.getResult().initial_kept, 50u);
}

class AppInitial : public TempDirTest {};

TEST_F(AppInitial, ReconstructTakesAnInitialMeshInEitherMode) {
  const std::string app = std::string(PCL_MS_BINARY_DIR) + "/pcl_ms_reconstruct";
  ASSERT_TRUE(fs::exists(app)) << app << " was not built";
  // A soup: the bunny mesh with a few of its triangles repeated and some
  // crossing ones, as OFF (another format than the PLY input).
  const ReferenceMesh &mesh = bunnyReference();
  std::string off = "OFF\n" + std::to_string(mesh.vertices.size()) + " " +
                    std::to_string(mesh.triangles.size() + 20) + " 0\n";
  char line[160];
  for (const Eigen::Vector3d &v : mesh.vertices) {
    std::snprintf(line, sizeof line, "%.9g %.9g %.9g\n", v.x(), v.y(), v.z());
    off += line;
  }
  auto face = [&](const Triangle &t) {
    off += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) +
           "\n";
  };
  for (const Triangle &triangle : mesh.triangles)
    face(triangle);
  for (int i = 0; i < 10; ++i)
    face(mesh.triangles[1000 * i]);
  for (int i = 0; i < 10; ++i)
    face({static_cast<pcl_ms::VertexIndex>(100 + i), static_cast<pcl_ms::VertexIndex>(12000 + i),
          static_cast<pcl_ms::VertexIndex>(24000 + i)});
  writeFile(path("soup.off"), off);
  const std::string files = quoted(dataPath("bunny.pcd")) + " " + quoted(path("out.ply")) +
                            " -initial " + quoted(path("soup.off"));

  ASSERT_EQ(runProgram(app, files + " -initial_mode preferred"), 0) << stderr_;
  EXPECT_TRUE(contains(stdout_, "initial triangles preferred")) << stdout_;
  EXPECT_TRUE(contains(stdout_, "initial repeats merged")) << stdout_;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Triangle> triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("out.ply"), vertices, triangles, error)) << error;
  expectCleanManifold(pcl_ms::analyzeMesh(vertices, triangles));
  const std::set<Triangle> output = sortedSet(triangles);
  EXPECT_GE(static_cast<double>(countIn(output, mesh.triangles)), 0.99 * mesh.triangles.size());

  // Fixed mode (the default) rejects the soup with the reason.
  EXPECT_NE(runProgram(app, files + " -q"), 0);
  EXPECT_TRUE(contains(stderr_, "error: ")) << stderr_;
  EXPECT_TRUE(contains(stderr_, "twice")) << stderr_;
  // Fixed mode takes a clean partial mesh: here bun0's own mesh, saved by
  // the tool, as PLY.
  const std::string bun0 = quoted(dataPath("bun0.pcd"));
  ASSERT_EQ(runProgram(app, bun0 + " " + quoted(path("bun0.ply")) + " -q"), 0) << stderr_;
  ASSERT_EQ(runProgram(app, bun0 + " " + quoted(path("again.ply")) + " -initial " +
                                quoted(path("bun0.ply")) + " -initial_mode fixed"),
            0)
      << stderr_;
  EXPECT_TRUE(contains(stdout_, "initial triangles fixed")) << stdout_;
  std::vector<Triangle> first, again;
  ASSERT_TRUE(pcl_ms::loadMesh(path("bun0.ply"), vertices, first, error)) << error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("again.ply"), vertices, again, error)) << error;
  EXPECT_EQ(countIn(sortedSet(again), first), first.size());

  EXPECT_NE(runProgram(app, files + " -initial_mode sometimes"), 0);
  EXPECT_TRUE(contains(stderr_, "not fixed or preferred")) << stderr_;
  EXPECT_NE(runProgram(app, quoted(dataPath("bunny.pcd")) + " " + quoted(path("out.ply")) +
                                " -initial_mode preferred"),
            0);
  EXPECT_TRUE(contains(stderr_, "needs -initial")) << stderr_;
}

TEST_F(AppInitial, VertexAtInfinityIsNotAPointOfTheCloud) {
  // The reconstruction skips non-finite points, so an -initial vertex at
  // +inf must not be matched to the cloud's point at +inf.
  const std::string app = std::string(PCL_MS_BINARY_DIR) + "/pcl_ms_reconstruct";
  ASSERT_TRUE(fs::exists(app)) << app << " was not built";
  writeFile(path("cloud.pcd"), "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
                               "COUNT 1 1 1\nWIDTH 5\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
                               "POINTS 5\nDATA ascii\n0 0 0\n1 0 0\n0 1 0\ninf 0 0\n1 1 0.1\n");
  writeFile(path("mesh.off"), "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\ninf 0 0\n3 0 1 2\n3 1 2 3\n");
  const std::string files = quoted(path("cloud.pcd")) + " " + quoted(path("out.ply")) +
                            " -initial " + quoted(path("mesh.off"));

  EXPECT_EQ(runProgram(app, files + " -q"), 1) << stderr_;
  EXPECT_TRUE(contains(stderr_, "vertex 3 of triangle 1 of ")) << stderr_;
  EXPECT_TRUE(contains(stderr_, "is not a point of")) << stderr_;
  EXPECT_FALSE(fs::exists(path("out.ply")));

  // Preferred mode leaves the triangle out and keeps the finite one.
  ASSERT_EQ(runProgram(app, files + " -initial_mode preferred"), 0) << stderr_;
  EXPECT_TRUE(contains(stdout_, "1 vertices not in the input")) << stdout_;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Triangle> triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("out.ply"), vertices, triangles, error)) << error;
  for (const Eigen::Vector3d &vertex : vertices)
    EXPECT_TRUE(vertex.allFinite()) << vertex.transpose();
  const auto corner = [&](const Eigen::Vector3d &position) {
    for (std::size_t v = 0; v < vertices.size(); ++v)
      if (vertices[v] == position)
        return static_cast<pcl_ms::VertexIndex>(v);
    return static_cast<pcl_ms::VertexIndex>(vertices.size());
  };
  const Triangle kept = sorted({corner({0, 0, 0}), corner({1, 0, 0}), corner({0, 1, 0})});
  ASSERT_LT(kept[2], vertices.size());
  EXPECT_EQ(sortedSet(triangles).count(kept), 1u);
}
