// SPDX-License-Identifier: GPL-3.0-or-later
// Buckets must not open holes that the one-piece mesh does not have. Each
// bucket keeps candidates below rho times its own d_med, a few percent off
// the whole cloud's: a uniform sampling dense enough for many buckets shows
// the small gaps this leaves where a bucket's threshold is the lower one.
#include "surface_sampling.h"
#include "test_support.h"

#include <algorithm>
#include <set>

namespace {

using namespace pcl_ms_test;

bool sharesAVertex(const std::vector<pcl_ms::VertexIndex> &loop,
                   const std::set<pcl_ms::VertexIndex> &vertices) {
  return std::any_of(loop.begin(), loop.end(),
                     [&](pcl_ms::VertexIndex v) { return vertices.count(v) > 0; });
}

TEST(BucketLoops, BucketsAddNoBoundaryLoopToAUniformSampling) {
  const ReferenceMesh &bunny = bunnyReference();
  // 300,000 points and buckets of 30,000: the setting where per-bucket
  // thresholds left four new loops on this sampling.
  const std::vector<Eigen::Vector3f> samples =
      pcl_ms_tools::sampleSurface(bunny.vertices, bunny.triangles, 300000, 1);
  std::vector<float> xyz;
  xyz.reserve(3 * samples.size());
  for (const Eigen::Vector3f &p : samples)
    xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});

  pcl_ms::Parameters one_piece;
  one_piece.num_threads = 2;
  pcl_ms::Parameters buckets = one_piece;
  buckets.bucket_points = 30000;
  const pcl_ms::Result whole = pcl_ms::reconstruct(viewOf(xyz), one_piece);
  const pcl_ms::Result bucketed = pcl_ms::reconstruct(viewOf(xyz), buckets);
  ASSERT_EQ(whole.bucket_statistics.buckets, 0u);
  ASSERT_GT(bucketed.bucket_statistics.buckets, 8u);
  // The sampled surface is open only at the five holes in the bunny's base.
  // Tight clusters of the random sample once held the local scale at a third
  // of its surroundings and left small holes there (6 loops on this
  // sampling, 14 on another 300,000-point one).
  EXPECT_EQ(whole.boundary_loops.size(), 5u);

  std::set<pcl_ms::VertexIndex> on_whole_loops;
  for (const auto &loop : whole.boundary_loops)
    on_whole_loops.insert(loop.begin(), loop.end());
  // A loop of the bucketed mesh may differ from the one-piece loop at the
  // same opening (its rim can run a vertex further), but must have one there.
  for (const auto &loop : bucketed.boundary_loops)
    EXPECT_TRUE(sharesAVertex(loop, on_whole_loops))
        << "a loop of " << loop.size() << " edges that the one-piece mesh lacks, at vertex "
        << loop.front();
  EXPECT_LE(bucketed.boundary_loops.size(), whole.boundary_loops.size());
  const pcl_ms::MeshTopologyReport report = pcl_ms::analyzeMesh(positions(xyz), bucketed.triangles);
  EXPECT_EQ(report.non_manifold_edges, 0u);
  EXPECT_EQ(report.non_manifold_vertices, 0u);
}

} // namespace
