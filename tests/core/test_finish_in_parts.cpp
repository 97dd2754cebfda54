// SPDX-License-Identifier: GPL-3.0-or-later
// The whole finishing over a triangle list held in parts
// (src/core/finish_in_parts.h): the same surface as finishSurface() in one
// process, for any split of the triangles and the points, threads standing
// in for processes.
#include "core_test_support.h"
#include "finish_in_parts.h"
#include "parts_test_support.h"
#include "thread_processes.h"

#include <gtest/gtest.h>
#include <pcl_ms/finish.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

using namespace pcl_ms;

namespace {

/// A holed patch of the bunny (every 31st triangle and runs of three every
/// 97 taken out, its triangles turned at random), with jittered Moebius
/// bands beside it: small ones whose twists are cut and refilled, round
/// after round, and one of 200 segments whose real twist stays.
std::vector<Eigen::Vector3d> crumpledSurface(std::vector<Triangle> &triangles) {
  std::vector<Eigen::Vector3d> points = pcl_ms_test::bunnyReference().vertices;
  const std::vector<Triangle> &all = pcl_ms_test::bunnyReference().triangles;
  std::mt19937 random(20261206);
  for (std::size_t t = 0; t < 20000; ++t)
    if (t % 31 != 0 && t % 97 >= 3) {
      Triangle turned = all[t];
      if (random() % 2 == 0)
        std::swap(turned[1], turned[2]);
      triangles.push_back(turned);
    }
  std::uniform_real_distribution<double> shake(-1, 1);
  int band = 0;
  for (const int segments : {6, 9, 16, 200}) {
    ++band;
    std::vector<Eigen::Vector3d> band_points;
    std::vector<Triangle> band_triangles;
    pcl_ms_test::moebiusBand(segments, 0.3, band_points, band_triangles);
    const auto offset = static_cast<VertexIndex>(points.size());
    const double jitter = segments == 200 ? 0.002 : 0.03;
    for (const Eigen::Vector3d &point : band_points)
      points.push_back(0.05 *
                       (point + Eigen::Vector3d(3 * band, 0, 0) +
                        jitter * Eigen::Vector3d(shake(random), shake(random), shake(random))));
    for (Triangle t : band_triangles) {
      for (VertexIndex &v : t)
        v += offset;
      triangles.push_back(t);
    }
  }
  return points;
}

} // namespace

TEST(FinishInParts, TheSurfaceIsOneProcesssForAnySplitWithOrWithoutAViewpoint) {
  std::vector<Triangle> triangles;
  const std::vector<Eigen::Vector3d> points = crumpledSurface(triangles);
  const std::size_t n = triangles.size(), point_count = points.size();
  const std::vector<float> scales = pcl_ms_test::varyingScales(point_count);
  constexpr int max_edges = 12;
  constexpr double rho = 5;
  const Eigen::Vector3d viewpoint(0.3, 0.4, 1.5);
  for (const Eigen::Vector3d *view : {static_cast<const Eigen::Vector3d *>(nullptr), &viewpoint}) {
    SCOPED_TRACE(view ? "with a viewpoint" : "without a viewpoint");
    const FinishedSurface expected =
        finishSurface(triangles, points, max_edges, SideLimit{&scales, rho}, nullptr, view);
    // Every step has work: holes filled, twists cut and refilled.
    ASSERT_GT(expected.holes_filled, 50u);
    ASSERT_GT(expected.twist_triangles_removed, 0u);
    // The band of 200 keeps its real twist, unless a viewpoint repairs it.
    EXPECT_EQ(std::count(expected.component_orientable.begin(), expected.component_orientable.end(),
                         false),
              view ? 0 : 1);

    const std::vector<std::vector<std::size_t>> splits = {
        {0, n},
        {0, n / 2, n},
        {0, n / 5, n / 5, n - 300, n},
        {0, 1, n / 3, n - 50, n - 1, n},
    };
    for (const std::vector<std::size_t> &cuts : splits) {
      const int processes = static_cast<int>(cuts.size()) - 1;
      SCOPED_TRACE(std::to_string(processes) + " processes");
      std::vector<detail::FinishedPart> parts(static_cast<std::size_t>(processes));
      pcl_ms_test::onThreadProcesses(processes, [&](ProcessGroup &group) {
        const auto p = static_cast<std::size_t>(group.process());
        const std::vector<Triangle> mine = pcl_ms_test::sliceOf(triangles, cuts[p], cuts[p + 1]);
        const pcl_ms_test::HomeSlice home =
            pcl_ms_test::homeSlice(points, p, processes, pcl_ms_test::HomeCut::uneven, scales);
        parts[p] = detail::finishInParts(mine, cuts[p], home.points, home.scales, home.begin,
                                         max_edges, rho, view, group);
      });
      std::vector<Triangle> finished;
      // Components numbered by their first triangles, as one process numbers them.
      std::vector<std::uint64_t> component_firsts;
      std::vector<std::uint32_t> triangle_component;
      std::vector<bool> component_orientable;
      for (int p = 0; p < processes; ++p) {
        const detail::FinishedPart &part = parts[static_cast<std::size_t>(p)];
        ASSERT_EQ(part.component.size(), part.triangles.size());
        ASSERT_EQ(part.orientable.size(), part.triangles.size());
        for (std::size_t t = 0; t < part.triangles.size(); ++t) {
          if (part.component[t] == part.first + t) {
            component_firsts.push_back(part.component[t]);
            component_orientable.push_back(part.orientable[t] != 0);
          }
          const auto at =
              std::lower_bound(component_firsts.begin(), component_firsts.end(), part.component[t]);
          ASSERT_NE(at, component_firsts.end());
          triangle_component.push_back(static_cast<std::uint32_t>(at - component_firsts.begin()));
        }
      }
      EXPECT_EQ(triangle_component, expected.triangle_component);
      EXPECT_EQ(component_orientable, expected.component_orientable);
      for (int p = 0; p < processes; ++p) {
        const detail::FinishedPart &part = parts[static_cast<std::size_t>(p)];
        EXPECT_EQ(part.first, finished.size()) << "process " << p;
        EXPECT_EQ(part.holes_filled, expected.holes_filled) << "process " << p;
        EXPECT_EQ(part.twist_triangles_removed, expected.twist_triangles_removed)
            << "process " << p;
        finished.insert(finished.end(), part.triangles.begin(), part.triangles.end());
      }
      EXPECT_EQ(finished, expected.triangles);
      EXPECT_EQ(parts[0].boundary_loops, expected.boundary_loops);
    }
  }
}
