// SPDX-License-Identifier: GPL-3.0-or-later
// The generators of src/tools/synthetic_clouds.h themselves (not the
// reconstruction): determinism, point counts, the density ratios they
// promise, and the geometry of the one-view scan.
#include "synthetic_clouds.h"

#include <pcl/kdtree/kdtree_flann.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <vector>

namespace {

using pcl_ms_tools::SyntheticCloud;
using pcl_ms_tools::SyntheticScan;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

/// A measured ratio must be within this share of the requested one. The
/// 20-nearest-neighbour estimate scatters by about 1/sqrt(20) a point; fitted
/// over 20,000 points, seeds 1 to 5 gave ratios within 7 % of the requested.
constexpr double kRatioTolerance = 0.15;
constexpr std::size_t kMeasuredPoints = 20000;

bool isFinite(const pcl::PointXYZ &p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

bool sameBits(const Cloud &a, const Cloud &b) {
  return a.size() == b.size() && a.width == b.width && a.height == b.height &&
         (a.empty() || std::memcmp(&a[0], &b[0], a.size() * sizeof(pcl::PointXYZ)) == 0) &&
         a.sensor_origin_ == b.sensor_origin_ &&
         a.sensor_orientation_.coeffs() == b.sensor_orientation_.coeffs();
}

/// Points per area around each point: k / (π r_k²), r_k the distance to the
/// k-th nearest other point.
std::vector<double> localDensities(const Cloud &cloud, int k = 20) {
  auto shared = std::make_shared<Cloud>(cloud);
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(shared);
  std::vector<int> indices;
  std::vector<float> squared_distances;
  std::vector<double> densities;
  densities.reserve(cloud.size());
  for (const pcl::PointXYZ &p : cloud) {
    tree.nearestKSearch(p, k + 1, indices, squared_distances); // the point itself comes first
    densities.push_back(k / (M_PI * squared_distances.back()));
  }
  return densities;
}

/// For a law density ∝ ratio^t: exp of the least-squares slope of log
/// density against t over the points that `use` accepts.
double fittedRatio(const Cloud &cloud, const std::function<double(const pcl::PointXYZ &)> &t,
                   const std::function<bool(const pcl::PointXYZ &)> &use) {
  const std::vector<double> densities = localDensities(cloud);
  double n = 0, st = 0, sy = 0, stt = 0, sty = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!use(cloud[i]))
      continue;
    const double x = t(cloud[i]), y = std::log(densities[i]);
    n += 1;
    st += x;
    sy += y;
    stt += x * x;
    sty += x * y;
  }
  return std::exp((n * sty - st * sy) / (n * stt - st * st));
}

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

void expectRatio(const char *cloud, double measured, double requested) {
  std::printf("  %s: requested density ratio %g, measured %.2f\n", cloud, requested, measured);
  EXPECT_NEAR(measured, requested, kRatioTolerance * requested) << cloud;
}

TEST(SyntheticClouds, FixedSeedGivesIdenticalClouds) {
  const std::vector<SyntheticCloud> first = pcl_ms_tools::syntheticClouds(7);
  const std::vector<SyntheticCloud> second = pcl_ms_tools::syntheticClouds(7);
  const std::vector<SyntheticCloud> other = pcl_ms_tools::syntheticClouds(8);
  ASSERT_EQ(first.size(), second.size());
  ASSERT_EQ(first.size(), other.size());
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].name, second[i].name);
    EXPECT_TRUE(sameBits(first[i].cloud, second[i].cloud)) << first[i].name;
    // The noise-free scan does not use its seed; every other cloud must.
    if (first[i].name != "box_scan_160x120") {
      EXPECT_FALSE(sameBits(first[i].cloud, other[i].cloud)) << first[i].name;
    }
  }
}

TEST(SyntheticClouds, PointCountsAsRequested) {
  EXPECT_EQ(pcl_ms_tools::sphereWithDensityGradient(5000).cloud.size(), 5000u);
  EXPECT_EQ(pcl_ms_tools::torusWithDensityBands(7000).cloud.size(), 7000u);
  EXPECT_EQ(pcl_ms_tools::annulusWithDensityGradient(3000).cloud.size(), 3000u);
  EXPECT_EQ(pcl_ms_tools::hemisphereWithDensityGradient(4000).cloud.size(), 4000u);
  for (const auto &[width, height] : {std::pair<int, int>{160, 120}, {640, 480}}) {
    const SyntheticScan scan = pcl_ms_tools::oneViewScanOfBoxOnPlane(width, height);
    EXPECT_EQ(scan.cloud.width, static_cast<std::uint32_t>(width));
    EXPECT_EQ(scan.cloud.height, static_cast<std::uint32_t>(height));
    EXPECT_EQ(scan.cloud.size(), static_cast<std::size_t>(width) * height);
  }
}

TEST(SyntheticClouds, TruthAsDocumented) {
  for (const SyntheticCloud &cloud : pcl_ms_tools::syntheticClouds()) {
    const auto &t = cloud.truth;
    EXPECT_EQ(t.components, 1u) << cloud.name;
    EXPECT_TRUE(t.orientable) << cloud.name;
    // A connected orientable surface: χ = 2 - 2 genus - loops.
    EXPECT_EQ((2 - t.euler_characteristic - static_cast<long long>(t.boundary_loops)) % 2, 0)
        << cloud.name;
  }
  EXPECT_EQ(pcl_ms_tools::sphereWithDensityGradient(100).truth.euler_characteristic, 2);
  EXPECT_EQ(pcl_ms_tools::torusWithDensityBands(100).truth.euler_characteristic, 0);
  EXPECT_EQ(pcl_ms_tools::annulusWithDensityGradient(100).truth.boundary_loops, 2u);
  EXPECT_EQ(pcl_ms_tools::hemisphereWithDensityGradient(100).truth.boundary_loops, 1u);
}

TEST(SyntheticClouds, PointsLieOnTheirSurfaces) {
  for (const pcl::PointXYZ &p : pcl_ms_tools::sphereWithDensityGradient().cloud)
    ASSERT_NEAR(std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z), 1.0, 1e-6);
  for (const pcl::PointXYZ &p : pcl_ms_tools::hemisphereWithDensityGradient().cloud) {
    ASSERT_NEAR(std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z), 1.0, 1e-6);
    ASSERT_GE(p.z, 0.0f);
  }
  for (const pcl::PointXYZ &p : pcl_ms_tools::torusWithDensityBands().cloud) {
    const double from_tube_circle = std::hypot(std::hypot(p.x, p.y) - 1.0, p.z);
    ASSERT_NEAR(from_tube_circle, 0.35, 1e-6);
  }
}

TEST(SyntheticClouds, SphereDensityRatioAsRequested) {
  const Cloud cloud = pcl_ms_tools::sphereWithDensityGradient(kMeasuredPoints, 25).cloud;
  expectRatio("sphere",
              fittedRatio(
                  cloud, [](const pcl::PointXYZ &p) { return (p.z + 1.0) / 2.0; },
                  [](const pcl::PointXYZ &) { return true; }),
              25);
}

TEST(SyntheticClouds, AnnulusDensityRatioAsRequested) {
  const Cloud cloud = pcl_ms_tools::annulusWithDensityGradient(kMeasuredPoints, 10).cloud;
  // Near a boundary the neighbours lie on one side only: leave those points out.
  const double margin = 0.08;
  expectRatio("annulus",
              fittedRatio(
                  cloud, [](const pcl::PointXYZ &p) { return (p.x + 1.0) / 2.0; },
                  [&](const pcl::PointXYZ &p) {
                    const double radius = std::hypot(p.x, p.y);
                    return radius > pcl_ms_tools::kAnnulusInnerRadius + margin &&
                           radius < pcl_ms_tools::kAnnulusOuterRadius - margin;
                  }),
              10);
}

TEST(SyntheticClouds, HemisphereDensityRatioAsRequested) {
  const Cloud cloud = pcl_ms_tools::hemisphereWithDensityGradient(kMeasuredPoints, 16).cloud;
  expectRatio("hemisphere",
              fittedRatio(
                  cloud, [](const pcl::PointXYZ &p) { return 1.0 - p.z; },
                  [](const pcl::PointXYZ &p) { return p.z > 0.1; }), // away from the rim
              16);
}

TEST(SyntheticClouds, TorusBandsHaveTheFullRatio) {
  const int bands = 6;
  const Cloud cloud = pcl_ms_tools::torusWithDensityBands(kMeasuredPoints, 9, bands).cloud;
  const std::vector<double> densities = localDensities(cloud);
  const double width = 2 * M_PI / bands;
  std::vector<double> dense, sparse;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    double theta = std::atan2(cloud[i].y, cloud[i].x);
    if (theta < 0)
      theta += 2 * M_PI;
    const int band = static_cast<int>(theta / width);
    const double into_band = theta - band * width;
    // The middle half of each band: well away from the transitions, and
    // from the neighbouring band by more than a sparse k-neighbourhood.
    if (into_band < 0.25 * width || into_band > 0.75 * width)
      continue;
    (band % 2 == 0 ? dense : sparse).push_back(densities[i]);
  }
  ASSERT_FALSE(dense.empty());
  ASSERT_FALSE(sparse.empty());
  expectRatio("torus bands", median(dense) / median(sparse), 9);
  // Half the bands are dense: 9 of every 10 points lie in them.
  EXPECT_NEAR(static_cast<double>(dense.size()) / (dense.size() + sparse.size()), 0.9, 0.03);
}

TEST(SyntheticClouds, AnnulusHasNoPointInsideTheInnerRadius) {
  const Cloud planar = pcl_ms_tools::annulusWithDensityGradient(6000, 10, 3).cloud;
  const Cloud noisy = pcl_ms_tools::annulusWithDensityGradient(6000, 10, 3, 2e-4).cloud;
  ASSERT_EQ(planar.size(), noisy.size());
  double squared_z = 0;
  for (std::size_t i = 0; i < planar.size(); ++i) {
    const double radius = std::hypot(planar[i].x, planar[i].y);
    ASSERT_GE(radius, pcl_ms_tools::kAnnulusInnerRadius - 1e-6);
    ASSERT_LE(radius, pcl_ms_tools::kAnnulusOuterRadius + 1e-6);
    ASSERT_EQ(planar[i].z, 0.0f);
    // The noise moves points out of the plane only.
    ASSERT_EQ(planar[i].x, noisy[i].x);
    ASSERT_EQ(planar[i].y, noisy[i].y);
    squared_z += noisy[i].z * noisy[i].z;
  }
  EXPECT_NEAR(std::sqrt(squared_z / noisy.size()), 2e-4, 0.1 * 2e-4);
}

/// Where a point of the noise-free scan may lie: on the ground or on a face
/// of the box that faces the sensor.
bool onGroundOrVisibleBoxFace(const Eigen::Vector3f &p, const pcl_ms_tools::BoxOnPlaneScene &s) {
  const float tolerance = 1e-4f;
  const Eigen::Vector3f &low = s.box_min, &high = s.box_max;
  const bool in_box =
      (p.array() >= low.array() - tolerance).all() && (p.array() <= high.array() + tolerance).all();
  if (std::abs(p.z() - s.ground_z) < tolerance)
    return !in_box; // the box's footprint is hidden under it
  if (!in_box)
    return false;
  for (int axis = 0; axis < 3; ++axis)
    for (const float face : {low[axis], high[axis]}) {
      const float outward = face == low[axis] ? -1.0f : 1.0f;
      if (std::abs(p[axis] - face) < tolerance && outward * (s.sensor[axis] - face) > 0)
        return true;
    }
  return false;
}

/// The pixel (column, row) that sees `p` from the cloud's own sensor pose.
Eigen::Vector2f pixelOf(const Eigen::Vector3f &p, const SyntheticScan &scan) {
  const Eigen::Vector3f in_sensor =
      scan.cloud.sensor_orientation_.conjugate() * (p - scan.cloud.sensor_origin_.head<3>());
  return {scan.focal_length_px * in_sensor.x() / in_sensor.z() + 0.5f * scan.cloud.width,
          scan.focal_length_px * in_sensor.y() / in_sensor.z() + 0.5f * scan.cloud.height};
}

TEST(SyntheticClouds, ScanIsOrganizedWithNaNsWhereRaysMiss) {
  const SyntheticScan scan = pcl_ms_tools::oneViewScanOfBoxOnPlane(160, 120);
  const Cloud &cloud = scan.cloud;
  ASSERT_TRUE(cloud.isOrganized());
  EXPECT_FALSE(cloud.is_dense);
  EXPECT_EQ(cloud.sensor_origin_.head<3>(), scan.scene.sensor);
  std::size_t missing = 0, box = 0, ground = 0;
  for (int v = 0; v < static_cast<int>(cloud.height); ++v)
    for (int u = 0; u < static_cast<int>(cloud.width); ++u) {
      const pcl::PointXYZ &point = cloud.at(u, v);
      if (!isFinite(point)) {
        ++missing;
        // Rays above the horizon or to the far ground: the sky is at the top,
        // so a missing pixel has only missing pixels above it.
        for (int above = 0; above < v; ++above)
          ASSERT_FALSE(isFinite(cloud.at(u, above))) << u << ", " << v;
        continue;
      }
      const Eigen::Vector3f p = point.getVector3fMap();
      ASSERT_TRUE(onGroundOrVisibleBoxFace(p, scan.scene)) << p.transpose();
      ASSERT_LE((p - scan.scene.sensor).norm(), scan.scene.max_range + 1e-4f);
      // Each point sits in its own pixel: organized as seen by the sensor.
      const Eigen::Vector2f pixel = pixelOf(p, scan);
      ASSERT_NEAR(pixel.x(), u + 0.5f, 1e-2f);
      ASSERT_NEAR(pixel.y(), v + 0.5f, 1e-2f);
      (p.z() > scan.scene.ground_z + 1e-4f ? box : ground) += 1;
    }
  std::printf("  scan: %zu NaN, %zu box, %zu ground pixels\n", missing, box, ground);
  EXPECT_GT(missing, cloud.size() / 10);
  EXPECT_GT(box, cloud.size() / 20);
  EXPECT_GT(ground, cloud.size() / 2);
  // The bottom row sees ground only (the near ground is always in range).
  for (int u = 0; u < static_cast<int>(cloud.width); ++u)
    EXPECT_TRUE(isFinite(cloud.at(u, cloud.height - 1)));
}

TEST(SyntheticClouds, ScanShadowLiesInsideTheFrame) {
  // The truth (two boundary loops) needs the box and the ground behind it
  // inside the frame and in range: above every box pixel of a column the
  // ground shows again before the sky.
  const SyntheticScan scan = pcl_ms_tools::oneViewScanOfBoxOnPlane(160, 120);
  const Cloud &cloud = scan.cloud;
  std::size_t box_columns = 0;
  for (int u = 0; u < static_cast<int>(cloud.width); ++u) {
    int highest_box_row = -1;
    for (int v = static_cast<int>(cloud.height) - 1; v >= 0; --v)
      if (isFinite(cloud.at(u, v)) && cloud.at(u, v).z > scan.scene.ground_z + 1e-4f)
        highest_box_row = v;
    if (highest_box_row < 0)
      continue;
    ++box_columns;
    ASSERT_GT(u, 0);
    ASSERT_LT(u, static_cast<int>(cloud.width) - 1);
    ASSERT_GE(highest_box_row, 3);
    for (int v = highest_box_row - 3; v < highest_box_row; ++v)
      ASSERT_TRUE(isFinite(cloud.at(u, v))) << u << ", " << v;
  }
  EXPECT_GT(box_columns, cloud.width / 8);
}

TEST(SyntheticClouds, ScanRangeNoiseGrowsWithRangeSquared) {
  const double sigma_at_one_metre = 0.0015;
  const SyntheticScan exact = pcl_ms_tools::oneViewScanOfBoxOnPlane(160, 120);
  const SyntheticScan noisy =
      pcl_ms_tools::oneViewScanOfBoxOnPlane(160, 120, 5, sigma_at_one_metre);
  ASSERT_EQ(exact.cloud.size(), noisy.cloud.size());
  const Eigen::Vector3f sensor = exact.scene.sensor;
  double squared_normalized = 0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < exact.cloud.size(); ++i) {
    ASSERT_EQ(isFinite(exact.cloud[i]), isFinite(noisy.cloud[i]));
    if (!isFinite(exact.cloud[i]))
      continue;
    const Eigen::Vector3f a = exact.cloud[i].getVector3fMap() - sensor;
    const Eigen::Vector3f b = noisy.cloud[i].getVector3fMap() - sensor;
    ASSERT_LT(a.normalized().cross(b.normalized()).norm(), 1e-5f); // moved along its ray
    const double range = a.norm();
    const double error = b.norm() - range;
    squared_normalized += std::pow(error / (sigma_at_one_metre * range * range), 2);
    ++count;
  }
  EXPECT_NEAR(std::sqrt(squared_normalized / count), 1.0, 0.05);
}

} // namespace
