// SPDX-License-Identifier: GPL-3.0-or-later
// Tests of the pcl_ms_reconstruct program (suite App) and of the tool
// helpers it runs: finite_vertices.h, normal_estimation.h. Every file they
// write goes to a fresh temporary directory.
#include "finite_vertices.h"
#include "normal_estimation.h"
#include "program_test.h"
#include "synthetic_clouds.h"
#include "test_support.h"

#include <pcl_ms/io.h>

#include <gtest/gtest.h>
#include <pcl/common/point_tests.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace pcl_ms_test;

const std::string kDataDir = PCL_MS_DATA_DIR;
const std::string kApp = std::string(PCL_MS_BINARY_DIR) + "/pcl_ms_reconstruct";

class App : public TempDirTest {
protected:
  /// Runs pcl_ms_reconstruct with `arguments`; returns its exit code and
  /// keeps what it printed in stdout_ and stderr_.
  int run(const std::string &arguments) { return runProgram(kApp, arguments); }

  /// Failure means a non-zero exit and exactly one line "error: ..." on stderr.
  void expectFailure(const std::string &arguments, const std::string &reason_part) {
    SCOPED_TRACE(arguments);
    EXPECT_NE(run(arguments), 0);
    EXPECT_TRUE(stderr_.rfind("error: ", 0) == 0) << stderr_;
    EXPECT_EQ(std::count(stderr_.begin(), stderr_.end(), '\n'), 1) << stderr_;
    EXPECT_TRUE(contains(stderr_, reason_part)) << stderr_;
  }

  void SetUp() override {
    TempDirTest::SetUp();
    ASSERT_TRUE(fs::exists(kApp)) << kApp << " was not built";
  }
};

TEST_F(App, ReconstructsBun0IntoEveryFormat) {
  const std::string input = "'" + kDataDir + "/bun0.pcd'";
  for (const char *name : {"bun0.ply", "bun0.vtk", "bun0.obj"}) {
    SCOPED_TRACE(name);
    ASSERT_EQ(run(input + " '" + path(name) + "'"), 0) << stdout_ << stderr_;
    EXPECT_TRUE(stderr_.empty()) << stderr_;
    EXPECT_TRUE(contains(stdout_, "triangles")) << stdout_;
    std::vector<Eigen::Vector3d> vertices;
    std::vector<pcl_ms::Triangle> triangles;
    std::string error;
    ASSERT_TRUE(pcl_ms::loadMesh(path(name), vertices, triangles, error)) << error;
    EXPECT_EQ(vertices.size(), 397u);
    EXPECT_GT(triangles.size(), 0u);
  }
  // The PLY output keeps the input's normals.
  pcl::PCLPointCloud2 cloud;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadPointCloud(path("bun0.ply"), cloud, error)) << error;
  EXPECT_TRUE(pcl_ms::hasNormals(cloud));
}

TEST_F(App, ReconstructsTheVerticesOfAnStlMesh) {
  // bun0's mesh written as an ASCII STL, each corner repeated in every facet
  // as exporters do: the program meshes the welded vertices, each position
  // once, which are the bun0 points the mesh uses.
  ASSERT_EQ(run(quoted(kDataDir + "/bun0.pcd") + " " + quoted(path("bun0.ply")) + " -q"), 0)
      << stderr_;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("bun0.ply"), vertices, triangles, error)) << error;
  std::ostringstream stl;
  stl.precision(9); // every float back exactly
  stl << "solid bun0\n";
  std::set<std::array<double, 3>> used;
  for (const pcl_ms::Triangle &triangle : triangles) {
    stl << "facet normal 0 0 0\nouter loop\n";
    for (pcl_ms::VertexIndex v : triangle) {
      const Eigen::Vector3d &p = vertices[v];
      stl << "vertex " << p.x() << " " << p.y() << " " << p.z() << "\n";
      used.insert({p.x(), p.y(), p.z()});
    }
    stl << "endloop\nendfacet\n";
  }
  stl << "endsolid bun0\n";
  writeFile(path("bun0.stl"), stl.str());

  ASSERT_EQ(run(quoted(path("bun0.stl")) + " " + quoted(path("out.ply"))), 0) << stderr_;
  EXPECT_TRUE(contains(stdout_, "triangles")) << stdout_;
  std::vector<Eigen::Vector3d> out_vertices;
  std::vector<pcl_ms::Triangle> out_triangles;
  ASSERT_TRUE(pcl_ms::loadMesh(path("out.ply"), out_vertices, out_triangles, error)) << error;
  EXPECT_EQ(out_vertices.size(), used.size());
  std::set<std::array<double, 3>> read;
  for (const Eigen::Vector3d &p : out_vertices)
    read.insert({p.x(), p.y(), p.z()});
  EXPECT_EQ(read, used);
  // The same points in another order: the same surface (compared as corner
  // positions, each triangle starting at its smallest corner).
  const auto surface = [](const std::vector<Eigen::Vector3d> &points,
                          const std::vector<pcl_ms::Triangle> &faces) {
    std::vector<std::array<std::array<double, 3>, 3>> result;
    for (const pcl_ms::Triangle &face : faces) {
      std::array<std::array<double, 3>, 3> corners;
      for (int k = 0; k < 3; ++k)
        corners[k] = {points[face[k]].x(), points[face[k]].y(), points[face[k]].z()};
      std::rotate(corners.begin(), std::min_element(corners.begin(), corners.end()), corners.end());
      result.push_back(corners);
    }
    std::sort(result.begin(), result.end());
    return result;
  };
  EXPECT_EQ(surface(out_vertices, out_triangles), surface(vertices, triangles));

  // A cut file is refused with the reason.
  writeFile(path("cut.stl"), stl.str().substr(0, stl.str().size() / 2));
  expectFailure(quoted(path("cut.stl")) + " " + quoted(path("cut.ply")), "cut.stl: line ");
}

TEST_F(App, OptionsAndQuietMode) {
  ASSERT_EQ(run("'" + kDataDir + "/bun0.pcd' '" + path("out.ply") +
                "' -rho 30 -fill_holes 10 -normals -threads 0 -q"),
            0)
      << stderr_;
  EXPECT_TRUE(stdout_.empty()) << stdout_;
  EXPECT_TRUE(stderr_.empty()) << stderr_;
  EXPECT_TRUE(fs::exists(path("out.ply")));
}

TEST_F(App, BucketsWithProgressAndSummary) {
  const std::string files = "'" + kDataDir + "/bunny.pcd' '" + path("out.ply") + "'";
  ASSERT_EQ(run(files + " -bucket_points 10000 -threads 2"), 0) << stderr_;
  // 35,947 points: 4 buckets and 3 seams, reported on stderr as they finish.
  EXPECT_TRUE(contains(stderr_, "buckets and seams 7/7")) << stderr_;
  EXPECT_TRUE(contains(stdout_, "seam triangles")) << stdout_;
  EXPECT_TRUE(fs::exists(path("out.ply")));

  ASSERT_EQ(run(files + " -grid 2 -q"), 0) << stderr_;
  EXPECT_TRUE(stdout_.empty()) << stdout_;
  EXPECT_TRUE(stderr_.empty()) << stderr_;

  expectFailure(files + " -bucket_points 50", "bucket size");
  expectFailure(files + " -bucket_points many", "-bucket_points");
  expectFailure(files + " -grid -2", "grid");
}

TEST_F(App, ViewpointFromThePcdOrGivenOrNone) {
  // An organized depth frame whose PCD VIEWPOINT is the sensor's position.
  const auto scan = pcl_ms_tools::oneViewScanOfBoxOnPlane(80, 60);
  ASSERT_EQ(pcl::io::savePCDFileBinary(path("scan.pcd"), scan.cloud), 0);
  const Eigen::Vector3d sensor = scan.scene.sensor.cast<double>();
  auto facingShare = [&] {
    std::vector<Eigen::Vector3d> vertices;
    std::vector<pcl_ms::Triangle> triangles;
    std::string error;
    EXPECT_TRUE(pcl_ms::loadMesh(path("out.ply"), vertices, triangles, error)) << error;
    std::size_t facing = 0;
    for (const pcl_ms::Triangle &t : triangles) {
      const Eigen::Vector3d &a = vertices[t[0]], &b = vertices[t[1]], &c = vertices[t[2]];
      facing += (b - a).cross(c - a).dot(sensor - a) > 0;
    }
    return triangles.empty() ? 0.0 : static_cast<double>(facing) / triangles.size();
  };
  const std::string input = quoted(path("scan.pcd")) + " " + quoted(path("out.ply"));
  ASSERT_EQ(run(input), 0) << stderr_;
  EXPECT_TRUE(contains(stdout_, "viewpoint -0.8,-1.6,1.4 (sensor origin)")) << stdout_;
  EXPECT_GE(facingShare(), 0.99);
  // From below the ground the surface turns its back to the sensor.
  ASSERT_EQ(run(input + " -viewpoint 0,0,-5"), 0) << stderr_;
  EXPECT_TRUE(contains(stdout_, "viewpoint 0,0,-5")) << stdout_;
  EXPECT_LE(facingShare(), 0.01);
  ASSERT_EQ(run(input + " -no_viewpoint"), 0) << stderr_;
  EXPECT_FALSE(contains(stdout_, "viewpoint")) << stdout_;
  expectFailure(input + " -viewpoint 1,2", "-viewpoint");
  expectFailure(input + " -viewpoint 0,nan,1", "viewpoint must be finite");
}

TEST_F(App, DepthFrameFilesLeaveOutPointsWithoutPositionUnlessKeepLayout) {
  // An organized frame with NaN where the rays miss: mesh viewers cannot
  // read NaN vertices, so by default they stay out of the file.
  const auto scan = pcl_ms_tools::oneViewScanOfBoxOnPlane(80, 60);
  ASSERT_EQ(pcl::io::savePCDFileBinary(path("scan.pcd"), scan.cloud), 0);
  std::size_t finite_points = 0;
  for (const auto &point : scan.cloud.points)
    finite_points += pcl::isFinite(point);
  ASSERT_LT(finite_points, scan.cloud.size());
  // The triangles as corner positions, comparable across vertex numberings.
  auto trianglesAsPositions = [&](const std::string &file, std::size_t expected_vertices) {
    std::vector<Eigen::Vector3d> vertices;
    std::vector<pcl_ms::Triangle> triangles;
    std::string error;
    EXPECT_TRUE(pcl_ms::loadMesh(path(file), vertices, triangles, error)) << error;
    EXPECT_EQ(vertices.size(), expected_vertices);
    std::vector<std::array<double, 9>> positions;
    for (const pcl_ms::Triangle &triangle : triangles) {
      std::array<double, 9> corners;
      for (int k = 0; k < 3; ++k)
        for (int axis = 0; axis < 3; ++axis)
          corners[3 * k + axis] = vertices[triangle[k]][axis];
      positions.push_back(corners);
    }
    return positions;
  };
  ASSERT_EQ(run(quoted(path("scan.pcd")) + " " + quoted(path("compact.ply")) + " -q"), 0)
      << stderr_;
  ASSERT_EQ(run(quoted(path("scan.pcd")) + " " + quoted(path("layout.ply")) + " -q -keep_layout"),
            0)
      << stderr_;
  const auto compact = trianglesAsPositions("compact.ply", finite_points);
  const auto layout = trianglesAsPositions("layout.ply", scan.cloud.size());
  EXPECT_GT(compact.size(), 1000u);
  EXPECT_EQ(compact, layout);
}

TEST(FiniteVertices, DropsOnlyUnusedPointsWithoutPosition) {
  pcl::PointCloud<pcl::PointXYZ> points;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  points.push_back({nan, 0, 0});
  points.push_back({0, 0, 0});
  points.push_back({1, 0, 0});
  points.push_back({0, nan, nan});
  points.push_back({0, 1, 0});
  points.width = 5;
  points.height = 1;
  points.is_dense = false;
  pcl::PolygonMesh mesh;
  pcl::toPCLPointCloud2(points, mesh.cloud);
  pcl::Vertices triangle;
  triangle.vertices = {1, 2, 4};
  mesh.polygons = {triangle};
  EXPECT_EQ(pcl_ms_tools::dropNonFiniteVertices(mesh), 2u);
  EXPECT_EQ(mesh.cloud.width * mesh.cloud.height, 3u);
  EXPECT_TRUE(mesh.cloud.is_dense);
  const std::vector<pcl::index_t> expected = {0, 1, 2};
  EXPECT_EQ(mesh.polygons[0].vertices, expected);
  pcl::PointCloud<pcl::PointXYZ> kept;
  pcl::fromPCLPointCloud2(mesh.cloud, kept);
  EXPECT_EQ(kept[2].y, 1.0f);
  // Nothing to drop: the mesh stays as it is.
  EXPECT_EQ(pcl_ms_tools::dropNonFiniteVertices(mesh), 0u);
  EXPECT_EQ(mesh.cloud.width, 3u);
}

TEST(NormalEstimation, PlaneNormalsFaceTheViewpointAndMissingPointsGetNone) {
  pcl::PointCloud<pcl::PointXYZ> points;
  for (int row = 0; row < 10; ++row)
    for (int column = 0; column < 10; ++column)
      points.push_back({0.1f * column, 0.1f * row, 0.0f});
  points[37].x = std::numeric_limits<float>::quiet_NaN();
  points.width = 10;
  points.height = 10;
  points.is_dense = false;
  pcl::PCLPointCloud2 cloud;
  pcl::toPCLPointCloud2(points, cloud);
  std::string error;
  ASSERT_TRUE(pcl_ms_tools::estimateNormals(cloud, 8, std::array<double, 3>{0.5, 0.5, -3.0}, error))
      << error;
  ASSERT_TRUE(pcl_ms::hasNormals(cloud));
  pcl::PointCloud<pcl::PointNormal> with_normals;
  pcl::fromPCLPointCloud2(cloud, with_normals);
  ASSERT_EQ(with_normals.size(), 100u);
  for (std::size_t i = 0; i < with_normals.size(); ++i) {
    if (i == 37) {
      EXPECT_TRUE(std::isnan(with_normals[i].normal_z));
      continue;
    }
    EXPECT_NEAR(with_normals[i].normal_z, -1.0f, 1e-4f) << i; // towards z = -3
  }
  // Normals are not estimated twice, nor from fewer than 3 neighbours.
  EXPECT_FALSE(pcl_ms_tools::estimateNormals(cloud, 8, std::nullopt, error));
  EXPECT_TRUE(contains(error, "already has normals")) << error;
  pcl::toPCLPointCloud2(points, cloud);
  EXPECT_FALSE(pcl_ms_tools::estimateNormals(cloud, 2, std::nullopt, error));
}

TEST_F(App, EstimatedNormalsGuideTheSurface) {
  const std::string files = "'" + kDataDir + "/bunny.pcd' '" + path("out.ply") + "'";
  ASSERT_EQ(run(files + " -estimate_normals 10"), 0) << stderr_;
  EXPECT_TRUE(contains(stdout_, "normals estimated (10 neighbours)")) << stdout_;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("out.ply"), vertices, triangles, error)) << error;
  EXPECT_GT(triangles.size(), 70000u); // the bunny's 35,947 points, closed but for its base
  expectFailure(files + " -estimate_normals 2", "at least 3 neighbours");
  expectFailure(files + " -estimate_normals 10 -normal_weight -1", "normal weight must be >= 0");
  expectFailure(files + " -normal_weight x", "-normal_weight");
  expectFailure(files + " -estimate_normals 10 -normals", "exclude each other");
  expectFailure("'" + kDataDir + "/bun0.pcd' '" + path("out.ply") + "' -estimate_normals 10",
                "already has normals");
}

TEST_F(App, HelpExitsCleanly) {
  EXPECT_EQ(run("-h"), 0);
  EXPECT_TRUE(contains(stdout_, "-rho")) << stdout_;
  EXPECT_TRUE(stderr_.empty()) << stderr_;
}

TEST_F(App, MissingInputFails) {
  expectFailure("'" + path("missing.pcd") + "' '" + path("out.ply") + "'", "does not exist");
  EXPECT_FALSE(fs::exists(path("out.ply")));
}

TEST_F(App, BadRhoFails) {
  const std::string files = "'" + kDataDir + "/bun0.pcd' '" + path("out.ply") + "'";
  expectFailure(files + " -rho -1", "rho");
  expectFailure(files + " -rho abc", "-rho");
  expectFailure(files + " -rho", "-rho");
  EXPECT_FALSE(fs::exists(path("out.ply")));
}

TEST_F(App, BadThreadsAndHolesFail) {
  const std::string files = "'" + kDataDir + "/bun0.pcd' '" + path("out.ply") + "'";
  expectFailure(files + " -threads -2", "thread");
  expectFailure(files + " -threads 1.5", "-threads");
  expectFailure(files + " -fill_holes -3", "hole");
}

TEST_F(App, UnknownOutputExtensionFails) {
  expectFailure("'" + kDataDir + "/bun0.pcd' '" + path("out.stl") + "'", ".stl");
  EXPECT_FALSE(fs::exists(path("out.stl")));
}

TEST_F(App, BadArgumentsFail) {
  expectFailure("'" + kDataDir + "/bun0.pcd'", "input and output");
  expectFailure("", "input and output");
  expectFailure("a.pcd b.ply c.ply", "input and output");
  expectFailure("'" + kDataDir + "/bun0.pcd' '" + path("out.ply") + "' -colour", "-colour");
}

TEST_F(App, NormalsRequestedButAbsentFails) {
  writeFile(path("plain.xyz"), "0 0 0\n1 0 0\n0 1 0\n1 1 0.1\n");
  expectFailure("'" + path("plain.xyz") + "' '" + path("out.ply") + "' -normals", "normal");
}

TEST_F(App, ReconstructionFailureIsReported) {
  // Collinear points cannot be meshed.
  writeFile(path("line.xyz"), "0 0 0\n1 0 0\n2 0 0\n3 0 0\n");
  expectFailure("'" + path("line.xyz") + "' '" + path("out.ply") + "'", "");
  EXPECT_FALSE(fs::exists(path("out.ply")));
}

TEST_F(App, UnwritableOutputFails) {
  expectFailure("'" + kDataDir + "/bun0.pcd' '" + path("no_such_dir/out.ply") + "'", "no_such_dir");
}

} // namespace
