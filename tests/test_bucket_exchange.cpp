// SPDX-License-Identifier: GPL-3.0-or-later
// pcl_ms::BucketExchange without MPI: threads stand in for processes, so
// the sharing of buckets and seams (docs/algorithm.md, "Across processes")
// is checked in every build, sanitizers included.
#include "core/thread_processes.h"
#include "test_support.h"

#include <pcl_ms/buckets.h>
#include <pcl_ms/reconstruct.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

namespace {

using namespace pcl_ms_test;

/// pcl_ms::BucketExchange over the threads' ThreadGroup.
class ThreadExchange : public pcl_ms::BucketExchange {
public:
  ThreadExchange(Hub &hub, int process) : hub_(hub), group_(hub, process) {}
  int processes() const override { return group_.processes(); }
  int process() const override { return group_.process(); }
  void maxOver(std::vector<float> &values) override {
    group_.combine(values, [](float a, float b) { return std::max(a, b); });
  }
  void maxOver(std::vector<std::uint8_t> &values) override {
    group_.combine(values, [](std::uint8_t a, std::uint8_t b) { return std::max(a, b); });
  }
  void sumOver(std::vector<double> &values) override {
    group_.combine(values, [](double a, double b) { return a + b; });
  }
  void moveTriangles(const std::vector<Transfer> &transfers) override {
    for (const Transfer &transfer : transfers) {
      if (transfer.from == process())
        hub_.posted()[process()] = transfer.triangles;
      hub_.wait();
      if (transfer.to == process())
        *transfer.triangles =
            std::move(*static_cast<std::vector<pcl_ms::Triangle> *>(hub_.posted()[transfer.from]));
      hub_.wait();
    }
  }
  void stageDone(const std::string &) override { ++stages; }

  int stages = 0;

private:
  Hub &hub_;
  ThreadGroup group_;
};

/// The shared-bucket tests: the bunny in buckets of 4,000 points, as one
/// process meshes it, is the reference the shared runs must match.
class BucketExchange : public ::testing::Test {
protected:
  void SetUp() override {
    cloud = loadXYZ("bunny.pcd");
    parameters.bucket_points = 4000;
    reference = pcl_ms::reconstruct(viewOf(*cloud), parameters);
    // Enough buckets and seams that sharing them is exercised at all.
    ASSERT_GE(reference.bucket_statistics.buckets, 8u);
    ASSERT_GT(reference.bucket_statistics.seam_triangles, 0u);
  }

  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud;
  pcl_ms::Parameters parameters;
  pcl_ms::Result reference;
};

TEST_F(BucketExchange, ProcessesGiveTheOneProcessMesh) {
  const pcl_ms::BucketStatistics &expected = reference.bucket_statistics;
  // 3 does not divide the buckets evenly; 24 leaves some processes without a leaf.
  for (int processes : {2, 3, 24}) {
    Hub hub(processes);
    std::vector<pcl_ms::Result> results(processes);
    std::vector<ThreadExchange> exchanges;
    for (int p = 0; p < processes; ++p)
      exchanges.emplace_back(hub, p);
    std::vector<std::thread> threads;
    for (int p = 0; p < processes; ++p)
      threads.emplace_back(
          [&, p] { results[p] = pcl_ms::reconstruct(viewOf(*cloud), parameters, exchanges[p]); });
    for (std::thread &thread : threads)
      thread.join();

    EXPECT_EQ(results[0].triangles, reference.triangles) << processes << " processes";
    EXPECT_EQ(results[0].boundary_loops, reference.boundary_loops) << processes << " processes";
    EXPECT_EQ(results[0].d_med, reference.d_med);
    for (int p = 0; p < processes; ++p) {
      const pcl_ms::BucketStatistics &got = results[p].bucket_statistics;
      EXPECT_EQ(got.buckets, expected.buckets);
      EXPECT_EQ(got.seam_zones, expected.seam_zones);
      EXPECT_EQ(got.margin_points, expected.margin_points) << "process " << p;
      EXPECT_EQ(got.seam_points, expected.seam_points) << "process " << p;
      EXPECT_EQ(got.seam_triangles, expected.seam_triangles) << "process " << p;
      EXPECT_EQ(got.failed_units, 0u);
      if (p > 0) {
        EXPECT_TRUE(results[p].triangles.empty()) << "process " << p;
      }
      // The buckets, then one stage per seam level.
      EXPECT_EQ(exchanges[p].stages, exchanges[0].stages);
    }
    EXPECT_GE(exchanges[0].stages, 4);
  }
}

/// A farm that builds a batch of tasks, meshes them on threads and hands
/// the outcomes back last first: the order and place of meshing must not
/// matter. It records how many units were in flight at most.
class BatchFarm : public pcl_ms::BucketExchange, public pcl_ms::UnitFarm {
public:
  explicit BatchFarm(const pcl_ms::Parameters &parameters) : parameters_(parameters) {}
  pcl_ms::UnitFarm *farm() override { return this; }
  void mesh(std::size_t count, const std::function<pcl_ms::BucketTask(std::size_t)> &make,
            const std::function<void(std::size_t, pcl_ms::BucketOutcome &&)> &done) override {
    constexpr std::size_t batch = 3;
    for (std::size_t begin = 0; begin < count; begin += batch) {
      const std::size_t end = std::min(count, begin + batch);
      std::vector<pcl_ms::BucketTask> tasks;
      for (std::size_t i = begin; i < end; ++i)
        tasks.push_back(make(i));
      most_in_flight = std::max(most_in_flight, tasks.size());
      std::vector<pcl_ms::BucketOutcome> outcomes(tasks.size());
      std::vector<std::thread> threads;
      for (std::size_t k = 0; k < tasks.size(); ++k)
        threads.emplace_back([&, k] { outcomes[k] = pcl_ms::meshBucket(tasks[k], parameters_); });
      for (std::thread &thread : threads)
        thread.join();
      for (std::size_t k = tasks.size(); k-- > 0;)
        done(begin + k, std::move(outcomes[k]));
      units += tasks.size();
    }
  }
  std::size_t units = 0, most_in_flight = 0;

private:
  pcl_ms::Parameters parameters_;
};

TEST_F(BucketExchange, AFarmGivesTheOneProcessMesh) {
  const pcl_ms::BucketStatistics &expected = reference.bucket_statistics;
  BatchFarm farm(parameters);
  const pcl_ms::Result result = pcl_ms::reconstruct(viewOf(*cloud), parameters, farm);
  EXPECT_EQ(result.triangles, reference.triangles);
  EXPECT_EQ(result.boundary_loops, reference.boundary_loops);
  EXPECT_EQ(result.d_med, reference.d_med);
  const pcl_ms::BucketStatistics &got = result.bucket_statistics;
  EXPECT_EQ(got.margin_points, expected.margin_points);
  EXPECT_EQ(got.seam_points, expected.seam_points);
  EXPECT_EQ(got.seam_triangles, expected.seam_triangles);
  // Every bucket went through the farm, and every zone with points to mesh.
  EXPECT_GE(farm.units, expected.buckets + 1);
  EXPECT_LE(farm.units, expected.buckets + expected.seam_zones);
  EXPECT_LE(farm.most_in_flight, 3u);
}

/// A farm that spoils the caller's cloud as soon as the core says it has
/// its own copy (what the MPI tool does to free rank 0's memory): the core
/// must not read the cloud after that.
class SpoilingFarm : public BatchFarm {
public:
  SpoilingFarm(const pcl_ms::Parameters &parameters, pcl::PointCloud<pcl::PointXYZ> &cloud)
      : BatchFarm(parameters), cloud_(cloud) {}
  void pointsPrepared() override {
    ++calls;
    for (pcl::PointXYZ &point : cloud_)
      point.x = point.y = point.z = std::numeric_limits<float>::quiet_NaN();
  }
  int calls = 0;

private:
  pcl::PointCloud<pcl::PointXYZ> &cloud_;
};

TEST_F(BucketExchange, TheCloudIsNotReadAfterThePointsArePrepared) {
  pcl::PointCloud<pcl::PointXYZ> spoilt = *cloud;
  SpoilingFarm farm(parameters, spoilt);
  const pcl_ms::Result result = pcl_ms::reconstruct(viewOf(spoilt), parameters, farm);
  EXPECT_EQ(farm.calls, 1);
  EXPECT_TRUE(std::isnan(spoilt[0].x));
  EXPECT_EQ(result.triangles, reference.triangles);
  EXPECT_EQ(result.boundary_loops, reference.boundary_loops);
  EXPECT_EQ(result.invalid_points, 0u);
}

TEST(BucketOwner, LeavesAreSharedInContiguousRanges) {
  // 10 leaves on 4 processes: 3, 2, 3, 2 (rounded down multiples).
  std::vector<int> owners;
  for (std::size_t leaf = 0; leaf < 10; ++leaf)
    owners.push_back(pcl_ms::bucketOwner(leaf, 10, 4));
  EXPECT_EQ(owners, (std::vector<int>{0, 0, 0, 1, 1, 2, 2, 2, 3, 3}));
  // More processes than leaves: each leaf its own process, some idle.
  EXPECT_EQ(pcl_ms::bucketOwner(0, 3, 8), 0);
  EXPECT_EQ(pcl_ms::bucketOwner(1, 3, 8), 2);
  EXPECT_EQ(pcl_ms::bucketOwner(2, 3, 8), 5);
}

} // namespace
