// SPDX-License-Identifier: GPL-3.0-or-later
// Buckets and stitching (paper §4), initial triangles, on real scans.
#include "test_support.h"

#include <pcl_ms/buckets.h>
#include <pcl_ms/medial_scaffold_reconstruction.h>

#include <algorithm>
#include <array>
#include <random>
#include <set>

namespace {

using namespace pcl_ms_test;
using pcl_ms::Triangle;

std::vector<Triangle> sortedTriangles(std::vector<Triangle> triangles) {
  for (Triangle &triangle : triangles)
    std::sort(triangle.begin(), triangle.end());
  std::sort(triangles.begin(), triangles.end());
  return triangles;
}

std::size_t commonTriangles(const std::vector<Triangle> &a, const std::vector<Triangle> &b) {
  const std::vector<Triangle> sa = sortedTriangles(a), sb = sortedTriangles(b);
  std::vector<Triangle> common;
  std::set_intersection(sa.begin(), sa.end(), sb.begin(), sb.end(), std::back_inserter(common));
  return common.size();
}

/// Each loop as its set of vertices, to compare loops of two meshes.
std::set<std::vector<pcl_ms::VertexIndex>>
loopVertexSets(const std::vector<std::vector<pcl_ms::VertexIndex>> &loops) {
  std::set<std::vector<pcl_ms::VertexIndex>> sets;
  for (auto loop : loops) {
    std::sort(loop.begin(), loop.end());
    sets.insert(loop);
  }
  return sets;
}

pcl_ms::Parameters onePiece(std::size_t points) {
  pcl_ms::Parameters parameters;
  parameters.bucket_points = points; // no larger than this: one piece
  return parameters;
}

/// Bucketed against one-piece meshing of the same cloud: the acceptance
/// rules of the seams.
void expectSeamsInvisible(const std::string &file, const pcl_ms::Parameters &bucketed,
                          std::size_t min_buckets) {
  const auto cloud = loadXYZ(file);
  const pcl_ms::Result whole = pcl_ms::reconstruct(viewOf(*cloud), onePiece(cloud->size()));
  const pcl_ms::Result pieces = pcl_ms::reconstruct(viewOf(*cloud), bucketed);
  EXPECT_EQ(whole.bucket_statistics.buckets, 0u);
  EXPECT_GE(pieces.bucket_statistics.buckets, min_buckets);
  EXPECT_EQ(pieces.bucket_statistics.seam_zones, pieces.bucket_statistics.buckets - 1);
  EXPECT_GT(pieces.bucket_statistics.seam_triangles, 0u);
  EXPECT_EQ(pieces.bucket_statistics.failed_units, 0u);

  const auto points = positions(*cloud);
  const pcl_ms::MeshTopologyReport report = pcl_ms::analyzeMesh(points, pieces.triangles);
  expectCleanManifold(report);
  EXPECT_EQ(report.components, 1u);

  const std::size_t common = commonTriangles(whole.triangles, pieces.triangles);
  EXPECT_GE(static_cast<double>(common), 0.99 * whole.triangles.size());
  EXPECT_GE(static_cast<double>(common), 0.99 * pieces.triangles.size());

  // No boundary loop that the one-piece mesh lacks: every loop runs mostly
  // through the vertices of one of its loops (a triangle more or less on a
  // hole's rim changes a loop, but does not make a new hole).
  EXPECT_LE(pieces.boundary_loops.size(), whole.boundary_loops.size());
  const auto whole_loops = loopVertexSets(whole.boundary_loops);
  for (const auto &loop : loopVertexSets(pieces.boundary_loops)) {
    std::size_t best_shared = 0;
    for (const auto &other : whole_loops) {
      std::vector<pcl_ms::VertexIndex> shared;
      std::set_intersection(loop.begin(), loop.end(), other.begin(), other.end(),
                            std::back_inserter(shared));
      best_shared = std::max(best_shared, shared.size());
    }
    EXPECT_GE(2 * best_shared, loop.size())
        << "a seam opened a loop of " << loop.size() << " edges";
  }
}

TEST(Buckets, MedianSplitSeamsMatchTheOnePieceMesh) {
  pcl_ms::Parameters parameters;
  parameters.bucket_points = 5000; // 35,947 points: 8 buckets, 7 seams
  expectSeamsInvisible("bunny.pcd", parameters, 8);
}

TEST(Buckets, GridSeamsMatchTheOnePieceMesh) {
  pcl_ms::Parameters parameters;
  parameters.grid_buckets = 3; // 27 cells of the bounding box, some empty
  expectSeamsInvisible("bunny.pcd", parameters, 8);
}

TEST(Buckets, FineGridOverFewPointsClosesTheSurface) {
  // 16 points of a lumpy ball in the finest grid: no cell holds two, so no
  // bucket has a spacing of its own. The cloud's spacing gives them margins
  // that reach their neighbours, and the seams close the surface as the
  // one-piece run does (it used to fail: "no bucket could be meshed"), up
  // to the diagonal of a quad.
  pcl::PointCloud<pcl::PointXYZ> cloud;
  std::mt19937 random(11);
  std::normal_distribution<float> direction;
  std::uniform_real_distribution<float> radius(0.9f, 1.1f);
  while (cloud.size() < 16) {
    Eigen::Vector3f p(direction(random), direction(random), direction(random));
    p = radius(random) * p.normalized();
    cloud.push_back(pcl::PointXYZ(p.x(), 0.8f * p.y(), 0.6f * p.z()));
  }
  const pcl_ms::Result whole = pcl_ms::reconstruct(viewOf(cloud), pcl_ms::Parameters());
  pcl_ms::Parameters gridded;
  gridded.grid_buckets = pcl_ms::max_grid_buckets;
  const pcl_ms::Result pieces = pcl_ms::reconstruct(viewOf(cloud), gridded);
  ASSERT_EQ(pieces.bucket_statistics.buckets, cloud.size()); // one point each
  EXPECT_EQ(pieces.bucket_statistics.failed_units, 0u);
  for (const pcl_ms::Result *result : {&whole, &pieces}) {
    const pcl_ms::MeshTopologyReport report =
        pcl_ms::analyzeMesh(positions(cloud), result->triangles);
    expectCleanManifold(report);
    EXPECT_EQ(report.components, 1u);
    EXPECT_EQ(report.boundary_loops, 0u);
    EXPECT_EQ(result->triangles.size(), 2 * cloud.size() - 4); // closed, every point used
  }
  EXPECT_GE(commonTriangles(pieces.triangles, whole.triangles), whole.triangles.size() - 2);
}

TEST(Buckets, TooManyBucketsForTheCloudIsExplained) {
  // Two triangles' corners in pairs 0.07 apart, the pairs a unit apart: in a
  // 3 x 3 x 3 grid each bucket's margin (from its pair's spacing) reaches no
  // third point, so no bucket can be meshed; the error says what to do.
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (const auto &p : std::vector<std::array<float, 3>>{{1.05f, 0.05f, 1},
                                                         {1.05f, 1.05f, 2},
                                                         {0.05f, 1.05f, 1},
                                                         {0, 0, 0},
                                                         {1, 0, 1},
                                                         {0, 1, 1}})
    cloud.push_back(pcl::PointXYZ(p[0], p[1], p[2]));
  EXPECT_FALSE(pcl_ms::reconstruct(viewOf(cloud), pcl_ms::Parameters()).triangles.empty());
  pcl_ms::Parameters gridded;
  gridded.grid_buckets = 3;
  try {
    pcl_ms::reconstruct(viewOf(cloud), gridded);
    ADD_FAILURE() << "meshed in buckets that cannot see their neighbours";
  } catch (const pcl_ms::ReconstructionError &error) {
    EXPECT_NE(std::string(error.what()).find("too many buckets for the cloud: use fewer or none"),
              std::string::npos)
        << error.what();
  }
}

TEST(Buckets, SameMeshForOneTwoAndEightThreads) {
  const auto cloud = loadXYZ("bun000.pcd");
  pcl_ms::Parameters parameters;
  parameters.bucket_points = 4000;
  parameters.num_threads = 1;
  const pcl_ms::Result reference = pcl_ms::reconstruct(viewOf(*cloud), parameters);
  ASSERT_GE(reference.bucket_statistics.buckets, 8u);
  for (int threads : {2, 8}) {
    parameters.num_threads = threads;
    std::size_t calls = 0, last_done = 0, last_total = 0;
    parameters.progress = [&](std::size_t done, std::size_t total) {
      ++calls;
      EXPECT_GT(done, last_done); // one at a time, counting up
      last_done = done;
      last_total = total;
    };
    const pcl_ms::Result result = pcl_ms::reconstruct(viewOf(*cloud), parameters);
    EXPECT_EQ(result.triangles, reference.triangles) << threads << " threads";
    EXPECT_EQ(result.boundary_loops, reference.boundary_loops) << threads << " threads";
    const std::size_t units =
        reference.bucket_statistics.buckets + reference.bucket_statistics.seam_zones;
    EXPECT_EQ(calls, units);
    EXPECT_EQ(last_done, units);
    EXPECT_EQ(last_total, units);
  }
}

// In one process each seam zone runs once the buckets it reads are meshed,
// whichever thread gets there: the mesh is the one thread's, zone by zone.
// Small enough for the thread sanitizer.
TEST(Buckets, ZonesMeshedAsReadyGiveTheOneThreadMesh) {
  const auto bunny = loadXYZ("bunny.pcd");
  pcl::PointCloud<pcl::PointXYZ> cloud; // every fourth point: 9,000
  for (std::size_t i = 0; i < bunny->size(); i += 4)
    cloud.push_back((*bunny)[i]);
  pcl_ms::Parameters parameters;
  parameters.bucket_points = pcl_ms::min_bucket_points;
  parameters.num_threads = 1;
  const pcl_ms::PointView view = viewOf(cloud);
  const pcl_ms::Result reference = pcl_ms::reconstruct(view, parameters);
  ASSERT_GE(reference.bucket_statistics.seam_zones, 7u);
  ASSERT_GT(reference.bucket_statistics.seam_triangles, 0u);
  for (int threads : {2, 4}) {
    parameters.num_threads = threads;
    const pcl_ms::Result result = pcl_ms::reconstruct(view, parameters);
    EXPECT_EQ(result.triangles, reference.triangles) << threads << " threads";
    EXPECT_EQ(result.bucket_statistics.seam_triangles, reference.bucket_statistics.seam_triangles);
    EXPECT_EQ(result.bucket_statistics.seam_points, reference.bucket_statistics.seam_points);
  }
}

TEST(Buckets, AutomaticChoiceDependsOnTheCloudSizeOnly) {
  pcl_ms::Parameters parameters;
  EXPECT_FALSE(pcl_ms::usesBuckets(pcl_ms::automatic_bucketing_threshold, parameters));
  EXPECT_TRUE(pcl_ms::usesBuckets(pcl_ms::automatic_bucketing_threshold + 1, parameters));
  parameters.num_threads = 8;
  EXPECT_FALSE(pcl_ms::usesBuckets(pcl_ms::automatic_bucketing_threshold, parameters));
  parameters.bucket_points = 1000;
  EXPECT_TRUE(pcl_ms::usesBuckets(1001, parameters));
  EXPECT_FALSE(pcl_ms::usesBuckets(1000, parameters));
  parameters.bucket_points = 0;
  parameters.grid_buckets = 2;
  EXPECT_TRUE(pcl_ms::usesBuckets(10, parameters));
}

TEST(Buckets, InvalidBucketParametersAreRejected) {
  const auto cloud = loadXYZ("bun0.pcd");
  pcl_ms::Parameters parameters;
  parameters.bucket_points = 10;
  EXPECT_THROW(pcl_ms::reconstruct(viewOf(*cloud), parameters), pcl_ms::ReconstructionError);
  EXPECT_NE(parameters.validate().find("bucket size"), std::string::npos);
  parameters.bucket_points = 0;
  parameters.grid_buckets = -1;
  EXPECT_NE(parameters.validate().find("grid"), std::string::npos);
  parameters.grid_buckets = pcl_ms::max_grid_buckets + 1;
  EXPECT_NE(parameters.validate().find("grid"), std::string::npos);
}

// A bucket is a self-contained unit: points in, triangles on its core out.
TEST(Buckets, OneUnitKeepsOnlyTrianglesOnItsCorePoints) {
  const auto cloud = loadXYZ("bun0.pcd");
  pcl_ms::BucketTask task;
  task.points = positions(*cloud);
  double middle = 0;
  for (const Eigen::Vector3d &p : task.points)
    middle += p.x() / task.points.size();
  for (const Eigen::Vector3d &p : task.points)
    task.core.push_back(p.x() < middle);
  const pcl_ms::BucketOutcome outcome = pcl_ms::meshBucket(task, pcl_ms::Parameters());
  ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  EXPECT_GT(outcome.d_med, 0);
  ASSERT_GT(outcome.triangles.size(), 100u);
  for (const Triangle &triangle : outcome.triangles)
    for (pcl_ms::VertexIndex v : triangle)
      EXPECT_TRUE(task.core[v]);

  pcl_ms::BucketTask collinear;
  for (int i = 0; i < 10; ++i)
    collinear.points.emplace_back(i, 2 * i, 0);
  collinear.core.assign(10, true);
  const pcl_ms::BucketOutcome failed = pcl_ms::meshBucket(collinear, pcl_ms::Parameters());
  EXPECT_NE(failed.error.find("collinear"), std::string::npos) << failed.error;
  EXPECT_TRUE(failed.triangles.empty());
}

// ---------------------------------------------------------------------------
// Initial triangles: the library's partial re-meshing, which stitching uses.

TEST(InitialTriangles, AreKeptAndTheSurfaceIsCompletedAroundThem) {
  const auto cloud = loadXYZ("bunny.pcd");
  const auto points = positions(*cloud);
  const pcl_ms::Result first = pcl_ms::reconstruct(viewOf(*cloud), pcl_ms::Parameters());
  // Keep the triangles of the left half; mesh the rest around them.
  double middle = 0;
  for (const Eigen::Vector3d &p : points)
    middle += p.x() / points.size();
  std::vector<Triangle> initial;
  for (const Triangle &triangle : first.triangles)
    if (points[triangle[0]].x() < middle && points[triangle[1]].x() < middle &&
        points[triangle[2]].x() < middle)
      initial.push_back(triangle);
  ASSERT_GT(initial.size(), 20000u);

  const pcl_ms::Result completed =
      pcl_ms::reconstruct(viewOf(*cloud), pcl_ms::Parameters(), initial);
  EXPECT_EQ(commonTriangles(initial, completed.triangles), initial.size());
  const pcl_ms::MeshTopologyReport report = pcl_ms::analyzeMesh(points, completed.triangles);
  expectCleanManifold(report);
  EXPECT_EQ(report.components, 1u);
  EXPECT_LE(report.boundary_loops, first.boundary_loops.size());
  EXPECT_GE(static_cast<double>(commonTriangles(first.triangles, completed.triangles)),
            0.99 * first.triangles.size());
}

TEST(InitialTriangles, ANonDelaunayTriangleStays) {
  // A flat 5 x 5 grid; the initial triangle spans four cells, so it is not
  // a Delaunay triangle; the rest is meshed around it, manifold.
  std::vector<float> xyz;
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x)
      xyz.insert(xyz.end(), {static_cast<float>(x), static_cast<float>(y), 0.0f});
  const std::vector<Triangle> initial = {{0, 2, 10}};
  const pcl_ms::Result result = pcl_ms::reconstruct(viewOf(xyz), pcl_ms::Parameters(), initial);
  EXPECT_EQ(commonTriangles(initial, result.triangles), 1u);
  const pcl_ms::MeshTopologyReport report = pcl_ms::analyzeMesh(positions(xyz), result.triangles);
  expectCleanManifold(report);
  EXPECT_GT(result.triangles.size(), 10u);
}

TEST(InitialTriangles, BadOnesAreRejectedWithAReason) {
  std::vector<float> xyz = fibonacciSphere(200);
  xyz[3 * 7] = std::numeric_limits<float>::quiet_NaN();
  xyz[3 * 9] = xyz[3 * 8]; // point 9 duplicates point 8
  xyz[3 * 9 + 1] = xyz[3 * 8 + 1];
  xyz[3 * 9 + 2] = xyz[3 * 8 + 2];
  auto expectRejected = [&](const std::vector<Triangle> &initial, const std::string &reason) {
    SCOPED_TRACE(reason);
    try {
      pcl_ms::reconstruct(viewOf(xyz), pcl_ms::Parameters(), initial);
      ADD_FAILURE() << "accepted";
    } catch (const pcl_ms::ReconstructionError &error) {
      EXPECT_NE(std::string(error.what()).find(reason), std::string::npos) << error.what();
    }
  };
  expectRejected({{0, 1, 500}}, "not a valid point");
  expectRejected({{0, 1, 7}}, "not a valid point");
  expectRejected({{0, 8, 9}}, "same position");
  expectRejected({{0, 1, 2}, {2, 1, 0}}, "twice");
  expectRejected({{0, 1, 2}, {0, 1, 3}, {0, 1, 4}}, "more than two");
}

TEST(InitialTriangles, PclClassTakesPolygons) {
  const auto cloud = loadXYZ("bun0.pcd");
  pcl::MedialScaffoldReconstruction<pcl::PointXYZ> reconstruction;
  reconstruction.setInputCloud(cloud);
  std::vector<pcl::Vertices> polygons;
  reconstruction.reconstruct(*cloud, polygons);
  ASSERT_GT(polygons.size(), 100u);

  const std::vector<pcl::Vertices> initial(polygons.begin(), polygons.begin() + 50);
  reconstruction.setInitialTriangles(initial);
  EXPECT_EQ(reconstruction.getInitialTriangles().size(), 50u);
  std::vector<pcl::Vertices> completed;
  reconstruction.reconstruct(*cloud, completed);
  EXPECT_TRUE(reconstruction.getErrorMessage().empty()) << reconstruction.getErrorMessage();
  std::set<std::vector<pcl::index_t>> output;
  for (pcl::Vertices polygon : completed) {
    std::sort(polygon.vertices.begin(), polygon.vertices.end());
    output.insert(polygon.vertices);
  }
  for (pcl::Vertices polygon : initial) {
    std::sort(polygon.vertices.begin(), polygon.vertices.end());
    EXPECT_TRUE(output.count(polygon.vertices));
  }

  pcl::Vertices quad;
  quad.vertices = {0, 1, 2, 3};
  reconstruction.setInitialTriangles({quad});
  reconstruction.reconstruct(*cloud, completed);
  EXPECT_TRUE(completed.empty());
  EXPECT_NE(reconstruction.getErrorMessage().find("not 3"), std::string::npos);
}

TEST(PclClass, BucketSettersReachTheCore) {
  const auto cloud = loadXYZ("bun000.pcd");
  pcl::MedialScaffoldReconstruction<pcl::PointXYZ> reconstruction;
  EXPECT_EQ(reconstruction.getBucketSize(), 0u);
  EXPECT_EQ(reconstruction.getGridBuckets(), 0);
  reconstruction.setInputCloud(cloud);
  reconstruction.setBucketSize(20000); // 40,256 points: two median splits
  reconstruction.setNumberOfThreads(2);
  EXPECT_EQ(reconstruction.getBucketSize(), 20000u);
  pcl::PolygonMesh mesh;
  reconstruction.reconstruct(mesh);
  EXPECT_EQ(reconstruction.getResult().bucket_statistics.buckets, 4u);
  EXPECT_EQ(mesh.polygons.size(), reconstruction.getResult().triangles.size());
  reconstruction.setBucketSize(0);
  reconstruction.setGridBuckets(2);
  EXPECT_EQ(reconstruction.getGridBuckets(), 2);
  reconstruction.reconstruct(mesh);
  // The single view fills 6 of the 8 cells.
  EXPECT_EQ(reconstruction.getResult().bucket_statistics.buckets, 6u);
}

} // namespace
