// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 1 with the records spread over processes (threads here): the
// slices, joined in process order, must be the points one process prepares,
// bit for bit, however the records are cut, so that everything after them
// gives the one-process mesh.
#include "core_test_support.h"
#include "thread_processes.h"

#include <pcl_ms/buckets.h>
#include <pcl_ms/prepared_points.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace {

using namespace pcl_ms_test;

/// The bunny with what preparation must handle: NaN and infinite records,
/// exact duplicates far apart in the record order (so in other parts), a
/// lone far stray point, a distant group of points (kept), and zeros of
/// both signs.
std::vector<float> awkwardBunny() {
  std::vector<float> xyz = bunnyCoordinates();
  const std::size_t n = xyz.size() / 3;
  auto add = [&](float x, float y, float z) {
    xyz.push_back(x);
    xyz.push_back(y);
    xyz.push_back(z);
  };
  for (std::size_t i = 0; i < n; i += 997) // duplicates, appended at the end
    add(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  xyz[3 * 5000] = nan;
  xyz[3 * 20000 + 2] = inf;
  add(nan, 0, 0);
  add(40.0f, -30.0f, 25.0f);  // a lone stray
  for (int k = 0; k < 4; ++k) // a far group: neighbours of each other, kept
    add(-50.0f + 0.001f * static_cast<float>(k), 60.0f, 0.0f);
  add(0.0f, -0.0f, 0.0f);
  add(-0.0f, 0.0f, -0.0f);
  return xyz;
}

/// Normals for `xyz`: mostly unit-ish, some zero, NaN or long.
std::vector<float> normalsFor(const std::vector<float> &xyz) {
  std::vector<float> normals(xyz.size());
  for (std::size_t i = 0; i < xyz.size(); ++i)
    normals[i] = std::sin(static_cast<float>(i) * 0.37f) * (i % 3 == 0 ? 3.0f : 1.0f);
  normals[3 * 7] = normals[3 * 7 + 1] = normals[3 * 7 + 2] = 0;
  normals[3 * 11 + 1] = std::numeric_limits<float>::quiet_NaN();
  return normals;
}

/// Record k of `cuts.size() - 1` consecutive parts starts at cuts[k].
std::vector<std::size_t> cutsFor(std::size_t records, const std::vector<double> &fractions) {
  std::vector<std::size_t> cuts{0};
  for (double fraction : fractions)
    cuts.push_back(static_cast<std::size_t>(fraction * static_cast<double>(records)));
  cuts.push_back(records);
  return cuts;
}

/// Process p's part of `xyz` (and `normals`, if any) cut at `cuts`.
pcl_ms::PointView partOf(const std::vector<float> &xyz, const std::vector<float> &normals,
                         const std::vector<std::size_t> &cuts, int p) {
  pcl_ms::PointView part;
  part.size = cuts[p + 1] - cuts[p];
  part.xyz = xyz.data() + 3 * cuts[p];
  if (!normals.empty())
    part.normals = normals.data() + 3 * cuts[p];
  return part;
}

struct Joined {
  pcl_ms::PreparedPoints points;
  pcl_ms::PreparationCounts counts;
};

/// Prepares `xyz` (and normals, if any) cut at `cuts`, one thread per part,
/// and joins the slices in process order, checking that they are
/// consecutive and that every process saw the same counts.
Joined prepareInParts(const std::vector<float> &xyz, const std::vector<float> &normals,
                      const std::vector<std::size_t> &cuts) {
  const int processes = static_cast<int>(cuts.size()) - 1;
  std::vector<pcl_ms::PreparedSlice> slices(processes);
  onThreadProcesses(processes, [&](pcl_ms::ProcessGroup &group) {
    const int p = group.process();
    slices[p] = pcl_ms::preparePointsTogether(partOf(xyz, normals, cuts, p), cuts[p],
                                              !normals.empty(), group);
  });
  Joined joined;
  joined.counts = slices[0].counts;
  joined.points.centre = slices[0].points.centre;
  for (const pcl_ms::PreparedSlice &slice : slices) {
    EXPECT_EQ(slice.first, joined.points.positions.size());
    EXPECT_EQ(slice.total, slices[0].total);
    EXPECT_EQ(slice.counts.input_points, joined.counts.input_points);
    EXPECT_EQ(slice.counts.invalid_points, joined.counts.invalid_points);
    EXPECT_EQ(slice.counts.duplicate_points, joined.counts.duplicate_points);
    EXPECT_EQ(slice.counts.far_points, joined.counts.far_points);
    EXPECT_EQ(slice.points.centre, joined.points.centre);
    const pcl_ms::PreparedPoints &part = slice.points;
    auto append = [](auto &to, const auto &from) { to.insert(to.end(), from.begin(), from.end()); };
    append(joined.points.positions, part.positions);
    append(joined.points.normals, part.normals);
    append(joined.points.user_index, part.user_index);
  }
  EXPECT_EQ(joined.points.positions.size(), slices[0].total);
  return joined;
}

pcl_ms::PointView viewWithNormals(const std::vector<float> &xyz,
                                  const std::vector<float> &normals) {
  pcl_ms::PointView view = viewOf(xyz);
  if (!normals.empty())
    view.normals = normals.data();
  return view;
}

void expectSamePreparation(const std::vector<float> &xyz, const std::vector<float> &normals,
                           const std::vector<std::vector<double>> &cuttings) {
  pcl_ms::Result one;
  const pcl_ms::PreparedPoints expected =
      pcl_ms::preparePoints(viewWithNormals(xyz, normals), !normals.empty(), false, one);
  for (const std::vector<double> &fractions : cuttings) {
    const std::string where = std::to_string(fractions.size() + 1) + " parts";
    const Joined joined = prepareInParts(xyz, normals, cutsFor(xyz.size() / 3, fractions));
    EXPECT_EQ(joined.points.centre, expected.centre) << where;
    EXPECT_EQ(joined.points.user_index, expected.user_index) << where;
    EXPECT_TRUE(joined.points.positions == expected.positions) << where;
    EXPECT_TRUE(joined.points.normals == expected.normals) << where;
    EXPECT_EQ(joined.counts.input_points, one.input_points) << where;
    EXPECT_EQ(joined.counts.invalid_points, one.invalid_points) << where;
    EXPECT_EQ(joined.counts.duplicate_points, one.duplicate_points) << where;
    EXPECT_EQ(joined.counts.far_points, one.far_points) << where;
  }
}

// One part; two even ones; three uneven; five with an empty one and a part
// of a single record.
const std::vector<std::vector<double>> cuttings = {
    {}, {0.5}, {0.13, 0.71}, {0.2, 0.2, 0.6, 0.6 + 1e-5}};

TEST(PrepareTogether, SlicesJoinIntoTheOneProcessPoints) {
  const std::vector<float> xyz = awkwardBunny();
  pcl_ms::Result one;
  pcl_ms::preparePoints(viewOf(xyz), false, false, one);
  // The cloud has what the test is about.
  ASSERT_EQ(one.invalid_points, 3u);
  ASSERT_GE(one.duplicate_points, 36u);
  ASSERT_EQ(one.far_points, 1u);
  expectSamePreparation(xyz, {}, cuttings);
}

TEST(PrepareTogether, NormalsTravelWithTheirPoints) {
  const std::vector<float> xyz = awkwardBunny();
  expectSamePreparation(xyz, normalsFor(xyz), cuttings);
}

TEST(PrepareTogether, TooFewPointsFailOnEveryProcessAsInOne) {
  // Two distinct points, repeated in every part, and NaN records.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<float> xyz = {0, 0, 0, 1, 2, 3, nan, 0, 0, 0, 0, 0, 1, 2, 3, 0, 0, 0};
  std::string expected;
  try {
    pcl_ms::reconstruct(viewOf(xyz), pcl_ms::Parameters());
  } catch (const pcl_ms::ReconstructionError &error) {
    expected = error.what();
  }
  ASSERT_NE(expected.find("need at least 3 distinct valid points, got 2"), std::string::npos)
      << expected;
  const std::vector<std::size_t> cuts = cutsFor(xyz.size() / 3, {0.34, 0.5});
  std::vector<std::string> errors(cuts.size() - 1);
  onThreadProcesses(static_cast<int>(cuts.size()) - 1, [&](pcl_ms::ProcessGroup &group) {
    const int p = group.process();
    try {
      pcl_ms::preparePointsTogether(partOf(xyz, {}, cuts, p), cuts[p], false, group);
    } catch (const pcl_ms::ReconstructionError &error) {
      errors[p] = error.what();
    }
  });
  for (const std::string &error : errors)
    EXPECT_EQ(error, expected);
}

// ---- buckets by owner: meshSlicesInBuckets through reconstructSlices ---------

/// Each process prepares its part of `xyz` and meshes the slices with the
/// others; returns every process's result (and its run of the surface, when
/// `runs` is given).
std::vector<pcl_ms::Result> reconstructInParts(const std::vector<float> &xyz,
                                               const std::vector<float> &normals,
                                               const std::vector<std::size_t> &cuts,
                                               const pcl_ms::Parameters &parameters,
                                               std::vector<pcl_ms::FinishedRun> *runs = nullptr) {
  const int processes = static_cast<int>(cuts.size()) - 1;
  std::vector<pcl_ms::Result> results(processes);
  if (runs)
    runs->assign(static_cast<std::size_t>(processes), pcl_ms::FinishedRun());
  onThreadProcesses(processes, [&](pcl_ms::ProcessGroup &group) {
    const int p = group.process();
    results[p] = pcl_ms::reconstructSlices(
        pcl_ms::preparePointsTogether(partOf(xyz, normals, cuts, p), cuts[p],
                                      parameters.use_normals, group),
        parameters, group, runs ? &(*runs)[static_cast<std::size_t>(p)] : nullptr);
  });
  return results;
}

/// reconstructSlices asked to leave the surface in runs: a bucketed cloud
/// without the medial axis gives the one-process triangles and components
/// in runs (process 0's result has none), the rest as gathered.
void expectTheSurfaceInRuns(const std::vector<float> &xyz, const std::vector<float> &normals,
                            const std::vector<std::size_t> &cuts,
                            const pcl_ms::Parameters &parameters, const pcl_ms::Result &reference) {
  std::vector<pcl_ms::FinishedRun> runs;
  const std::vector<pcl_ms::Result> results =
      reconstructInParts(xyz, normals, cuts, parameters, &runs);
  const bool in_runs = reference.bucket_statistics.buckets > 0 && !parameters.compute_medial_axis;
  const std::string where = std::to_string(results.size()) + " processes, in runs";
  std::vector<pcl_ms::Triangle> triangles;
  std::vector<std::uint32_t> components;
  for (const pcl_ms::FinishedRun &run : runs) {
    EXPECT_EQ(run.used, in_runs) << where;
    EXPECT_EQ(run.first, triangles.size()) << where;
    EXPECT_EQ(run.total, in_runs ? reference.triangles.size() : 0u) << where;
    EXPECT_EQ(run.triangles.size(), run.component.size()) << where;
    triangles.insert(triangles.end(), run.triangles.begin(), run.triangles.end());
    components.insert(components.end(), run.component.begin(), run.component.end());
  }
  if (in_runs) {
    EXPECT_EQ(triangles, reference.triangles) << where;
    EXPECT_EQ(components, reference.triangle_component) << where;
    EXPECT_TRUE(results[0].triangles.empty()) << where;
    EXPECT_TRUE(results[0].triangle_component.empty()) << where;
  } else {
    EXPECT_EQ(results[0].triangles, reference.triangles) << where;
  }
  EXPECT_EQ(results[0].boundary_loops, reference.boundary_loops) << where;
  EXPECT_EQ(results[0].component_orientable, reference.component_orientable) << where;
  EXPECT_EQ(results[0].holes_filled, reference.holes_filled) << where;
  EXPECT_EQ(results[0].twist_triangles_removed, reference.twist_triangles_removed) << where;
}

void expectOneProcessMesh(const std::vector<float> &xyz, const std::vector<float> &normals,
                          const pcl_ms::Parameters &parameters,
                          const std::vector<std::vector<double>> &cuttings) {
  const pcl_ms::Result reference = pcl_ms::reconstruct(viewWithNormals(xyz, normals), parameters);
  const pcl_ms::BucketStatistics &expected = reference.bucket_statistics;
  for (const std::vector<double> &fractions : cuttings) {
    const std::vector<pcl_ms::Result> results =
        reconstructInParts(xyz, normals, cutsFor(xyz.size() / 3, fractions), parameters);
    const std::string where = std::to_string(results.size()) + " processes";
    EXPECT_EQ(results[0].triangles, reference.triangles) << where;
    EXPECT_EQ(results[0].boundary_loops, reference.boundary_loops) << where;
    EXPECT_EQ(results[0].triangle_component, reference.triangle_component) << where;
    EXPECT_EQ(results[0].component_orientable, reference.component_orientable) << where;
    EXPECT_EQ(results[0].holes_filled, reference.holes_filled) << where;
    EXPECT_EQ(results[0].twist_triangles_removed, reference.twist_triangles_removed) << where;
    EXPECT_EQ(results[0].d_med, reference.d_med) << where;
    ASSERT_EQ(results[0].medial_axis.has_value(), reference.medial_axis.has_value()) << where;
    if (reference.medial_axis) {
      EXPECT_EQ(results[0].medial_axis->node_positions, reference.medial_axis->node_positions)
          << where;
    }
    for (const pcl_ms::Result &result : results) {
      // One piece is process 0's alone; the buckets' figures are everyone's.
      if (expected.buckets > 0) {
        EXPECT_EQ(result.d_med, reference.d_med) << where;
      }
      EXPECT_EQ(result.duplicate_points, reference.duplicate_points) << where;
      const pcl_ms::BucketStatistics &got = result.bucket_statistics;
      EXPECT_EQ(got.buckets, expected.buckets) << where;
      EXPECT_EQ(got.seam_zones, expected.seam_zones) << where;
      EXPECT_EQ(got.margin_points, expected.margin_points) << where;
      EXPECT_EQ(got.seam_points, expected.seam_points) << where;
      EXPECT_EQ(got.seam_triangles, expected.seam_triangles) << where;
      EXPECT_EQ(got.failed_units, expected.failed_units) << where;
    }
    EXPECT_EQ(results[0].bucket_statistics.bow_tie_triangles_removed,
              expected.bow_tie_triangles_removed);
    for (std::size_t p = 1; p < results.size(); ++p)
      EXPECT_TRUE(results[p].triangles.empty()) << "process " << p;
    expectTheSurfaceInRuns(xyz, normals, cutsFor(xyz.size() / 3, fractions), parameters, reference);
  }
}

TEST(BucketsByOwner, MedianSplitsGiveTheOneProcessMesh) {
  pcl_ms::Parameters parameters;
  parameters.bucket_points = 4000;
  // 2 processes; 3 uneven; 5 with an empty one (it owns buckets, no points).
  expectOneProcessMesh(awkwardBunny(), {}, parameters, {{0.5}, {0.13, 0.71}, {0.2, 0.2, 0.6, 0.9}});
}

TEST(BucketsByOwner, GridAndNormalsGiveTheOneProcessMesh) {
  const std::vector<float> xyz = awkwardBunny();
  pcl_ms::Parameters parameters;
  parameters.grid_buckets = 3;
  parameters.use_normals = true;
  parameters.num_threads = 2;
  expectOneProcessMesh(xyz, normalsFor(xyz), parameters, {{0.4, 0.45}});
}

TEST(BucketsByOwner, AViewpointAndTheMedialAxisGiveTheOneProcessSurface) {
  // Finished in parts, the triangles turned towards the viewpoint; the
  // medial axis from the points process 0 receives at the end.
  pcl_ms::Parameters parameters;
  parameters.bucket_points = 3000;
  parameters.viewpoint = {{0.3, 0.4, 1.5}};
  parameters.compute_medial_axis = true;
  expectOneProcessMesh(awkwardBunny(), {}, parameters, {{0.5}, {0.1, 0.3, 0.8}});
}

TEST(BucketsByOwner, ANoisyBunnyGivesTheOneProcessSurface) {
  // Noise makes bow-ties at the seams (split in parts after the buckets)
  // and twists that the finishing cuts and refills.
  std::vector<float> xyz = awkwardBunny();
  std::mt19937 random(7);
  std::uniform_real_distribution<float> shake(-0.0005f, 0.0005f);
  for (float &coordinate : xyz)
    coordinate += shake(random);
  pcl_ms::Parameters parameters;
  parameters.bucket_points = 2000;
  const pcl_ms::Result reference = pcl_ms::reconstruct(viewOf(xyz), parameters);
  ASSERT_GT(reference.bucket_statistics.bow_tie_triangles_removed, 0u);
  ASSERT_GT(reference.twist_triangles_removed, 0u);
  expectOneProcessMesh(xyz, {}, parameters, {{0.5}, {0.2, 0.6, 0.7}});
}

TEST(BucketsByOwner, OnePieceIsMeshedByProcessZero) {
  const std::vector<float> xyz = fibonacciSphere(2000);
  expectOneProcessMesh(xyz, {}, pcl_ms::Parameters(), {{0.5}, {0.3, 0.6}});
}

TEST(BucketsByOwner, FewPointsInAFineGrid) {
  // One point a bucket: the margins come from the whole cloud's spacing.
  const std::vector<float> xyz = fibonacciSphere(16);
  pcl_ms::Parameters parameters;
  parameters.grid_buckets = pcl_ms::max_grid_buckets;
  expectOneProcessMesh(xyz, {}, parameters, {{0.5}, {0.25, 0.5, 0.75}});
}

TEST(BucketsByOwner, NoBucketMeshedFailsOnEveryProcessAsInOne) {
  const std::vector<float> xyz = {1.05f, 0.05f, 1, 1.05f, 1.05f, 2, 0.05f, 1.05f, 1,
                                  0,     0,     0, 1,     0,     1, 0,     1,     1};
  pcl_ms::Parameters parameters;
  parameters.grid_buckets = 3;
  std::string expected;
  try {
    pcl_ms::reconstruct(viewOf(xyz), parameters);
  } catch (const pcl_ms::ReconstructionError &error) {
    expected = error.what();
  }
  ASSERT_NE(expected.find("no bucket could be meshed"), std::string::npos) << expected;
  const std::vector<std::size_t> cuts = cutsFor(6, {0.34, 0.67});
  std::vector<std::string> errors(3);
  onThreadProcesses(3, [&](pcl_ms::ProcessGroup &group) {
    const int p = group.process();
    try {
      pcl_ms::reconstructSlices(
          pcl_ms::preparePointsTogether(partOf(xyz, {}, cuts, p), cuts[p], false, group),
          parameters, group);
    } catch (const pcl_ms::ReconstructionError &error) {
      errors[p] = error.what();
    }
  });
  for (const std::string &error : errors)
    EXPECT_EQ(error, expected);
}

} // namespace
