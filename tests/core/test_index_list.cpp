// SPDX-License-Identifier: GPL-3.0-or-later
// PointView::indices in every integer type pcl::Indices may have (32 or 64
// bits, signed or not): the same subset gives the same mesh, and entries
// outside the cloud are rejected whatever their type.
#include "core_test_support.h"

#include <cstdint>
#include <limits>
#include <vector>

namespace {

using pcl_ms_test::fibonacciSphere;
using pcl_ms_test::viewOf;

/// Two spheres; the indices pick the second one, in reverse order.
std::vector<float> twoSpheres() {
  std::vector<float> xyz = fibonacciSphere(300);
  const std::vector<float> far = fibonacciSphere(300, 1.0, {5, 0, 0});
  xyz.insert(xyz.end(), far.begin(), far.end());
  return xyz;
}

template <typename Integer> std::vector<Integer> secondSphere() {
  std::vector<Integer> indices;
  for (int i = 599; i >= 300; --i)
    indices.push_back(static_cast<Integer>(i));
  return indices;
}

template <typename Integer>
pcl_ms::Result meshSubset(const std::vector<float> &xyz, const std::vector<Integer> &indices) {
  pcl_ms::PointView view = viewOf(xyz);
  view.indices = pcl_ms::IndexList(indices);
  return pcl_ms::reconstruct(view, pcl_ms::Parameters());
}

TEST(IndexList, EveryIndexTypeGivesTheSameMesh) {
  const std::vector<float> xyz = twoSpheres();
  const pcl_ms::Result narrow = meshSubset(xyz, secondSphere<std::int32_t>());
  ASSERT_EQ(narrow.triangles.size(), 2u * 300 - 4); // a closed sphere
  for (const pcl_ms::Triangle &triangle : narrow.triangles)
    for (pcl_ms::VertexIndex corner : triangle)
      EXPECT_GE(corner, 300u);
  EXPECT_EQ(meshSubset(xyz, secondSphere<std::uint32_t>()).triangles, narrow.triangles);
  EXPECT_EQ(meshSubset(xyz, secondSphere<std::int64_t>()).triangles, narrow.triangles);
  EXPECT_EQ(meshSubset(xyz, secondSphere<std::uint64_t>()).triangles, narrow.triangles);
}

TEST(IndexList, EntriesOutsideTheCloudAreRejected) {
  const std::vector<float> xyz = twoSpheres();
  std::vector<std::int32_t> negative = secondSphere<std::int32_t>();
  negative[5] = -3;
  EXPECT_THROW(meshSubset(xyz, negative), pcl_ms::ReconstructionError);
  std::vector<std::uint64_t> huge = secondSphere<std::uint64_t>();
  huge[7] = std::numeric_limits<std::uint64_t>::max();
  EXPECT_THROW(meshSubset(xyz, huge), pcl_ms::ReconstructionError);
  std::vector<std::int64_t> past_end = secondSphere<std::int64_t>();
  past_end[0] = 600;
  EXPECT_THROW(meshSubset(xyz, past_end), pcl_ms::ReconstructionError);
}

// An empty list selects no point, which is an error, not the whole cloud.
TEST(IndexList, AnEmptyListSelectsNoPoint) {
  const std::vector<float> xyz = twoSpheres();
  EXPECT_THROW(meshSubset(xyz, std::vector<std::int32_t>()), pcl_ms::ReconstructionError);
  EXPECT_THROW(meshSubset(xyz, std::vector<std::uint64_t>()), pcl_ms::ReconstructionError);
}

} // namespace
