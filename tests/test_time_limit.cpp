// SPDX-License-Identifier: GPL-3.0-or-later
// The optional time limit: past it a run stops with a clear error and no
// mesh, in the one-piece and the bucketed paths, the PCL class and the tool.
#include "program_test.h"
#include "test_support.h"

#include <pcl_ms/deadline.h>
#include <pcl_ms/greedy.h>
#include <pcl_ms/medial_scaffold_reconstruction.h>

#include <filesystem>
#include <limits>
#include <utility>

namespace {

using namespace pcl_ms_test;

std::vector<float> bunnyCoordinates() {
  const auto cloud = loadXYZ("bunny.pcd");
  std::vector<float> xyz;
  for (const auto &p : *cloud)
    xyz.insert(xyz.end(), {p.x, p.y, p.z});
  return xyz;
}

std::string timeLimitError(const std::vector<float> &xyz, pcl_ms::Parameters parameters) {
  try {
    pcl_ms::reconstruct(viewOf(xyz), parameters);
  } catch (const pcl_ms::TimeLimitExceeded &error) {
    return error.what();
  }
  return "";
}

TEST(TimeLimit, AnExpiredLimitStopsTheOnePiecePath) {
  pcl_ms::Parameters parameters;
  parameters.time_limit_seconds = 1e-9;
  const std::string error = timeLimitError(bunnyCoordinates(), parameters);
  EXPECT_NE(error.find("time limit"), std::string::npos) << error;
  EXPECT_NE(error.find("no mesh"), std::string::npos) << error;
}

TEST(TimeLimit, TheGreedyPassesAreStoppedFromInside) {
  // The greedy runs a single loop for most of the run: a deadline already
  // passed when it starts must stop it there, not after it.
  const std::vector<float> xyz = bunnyCoordinates();
  std::vector<Eigen::Vector3d> points = positions(xyz);
  pcl_ms::ScaffoldOptions options;
  pcl_ms::MedialScaffold scaffold = pcl_ms::buildMedialScaffold(points, options);
  const pcl_ms::Deadline expired(1e-9);
  const pcl_ms::Parameters parameters; // outlives the mesher, which keeps a reference
  pcl_ms::GreedyMesher mesher(std::move(scaffold), points, parameters, &expired);
  EXPECT_THROW(mesher.run(), pcl_ms::TimeLimitExceeded);
}

TEST(TimeLimit, AnExpiredLimitStopsTheBuckets) {
  pcl_ms::Parameters parameters;
  parameters.bucket_points = 10000;
  parameters.num_threads = 2;
  parameters.time_limit_seconds = 1e-9;
  const std::string error = timeLimitError(bunnyCoordinates(), parameters);
  EXPECT_NE(error.find("time limit"), std::string::npos) << error;
}

TEST(TimeLimit, AGenerousLimitChangesNothing) {
  const std::vector<float> xyz = fibonacciSphere(2000);
  pcl_ms::Parameters limited;
  limited.time_limit_seconds = 600;
  const pcl_ms::Result with_limit = pcl_ms::reconstruct(viewOf(xyz), limited);
  const pcl_ms::Result without = pcl_ms::reconstruct(viewOf(xyz), pcl_ms::Parameters());
  EXPECT_EQ(with_limit.triangles, without.triangles);
}

TEST(TimeLimit, NegativeOrNaNLimitsAreRejected) {
  pcl_ms::Parameters parameters;
  parameters.time_limit_seconds = -1;
  EXPECT_NE(parameters.validate().find("time limit"), std::string::npos);
  parameters.time_limit_seconds = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(parameters.validate().find("time limit"), std::string::npos);
}

TEST(TimeLimit, ThePclClassReportsItAndGivesNoPolygons) {
  pcl::MedialScaffoldReconstruction<pcl::PointXYZ> reconstruction;
  EXPECT_EQ(reconstruction.getTimeLimit(), 0.0);
  reconstruction.setInputCloud(loadXYZ("bunny.pcd"));
  reconstruction.setTimeLimit(1e-9);
  pcl::PolygonMesh mesh;
  reconstruction.reconstruct(mesh);
  EXPECT_TRUE(mesh.polygons.empty());
  EXPECT_NE(reconstruction.getErrorMessage().find("time limit"), std::string::npos);
}

class TimeLimitTool : public TempDirTest {};

TEST_F(TimeLimitTool, TheToolFailsWithoutWritingAFile) {
  const std::string tool = std::string(PCL_MS_BINARY_DIR) + "/pcl_ms_reconstruct";
  const int status = runProgram(tool, quoted(dataPath("bunny.pcd")) + " " +
                                          quoted(path("mesh.ply")) + " -time_limit 0.000000001");
  EXPECT_NE(status, 0);
  EXPECT_NE(stderr_.find("time limit"), std::string::npos) << stderr_;
  EXPECT_FALSE(std::filesystem::exists(path("mesh.ply")));
  EXPECT_NE(runProgram(tool, quoted(dataPath("bunny.pcd")) + " " + quoted(path("mesh.ply")) +
                                 " -time_limit -3"),
            0);
  EXPECT_NE(stderr_.find("time limit"), std::string::npos) << stderr_;
}

} // namespace
