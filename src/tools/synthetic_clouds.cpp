// SPDX-License-Identifier: GPL-3.0-or-later
#include "synthetic_clouds.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

namespace pcl_ms_tools {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Uniform and normal numbers computed from the raw 64-bit output, so that
/// they do not depend on the standard library's distribution algorithms.
class PortableRandom {
public:
  explicit PortableRandom(std::uint64_t seed) : engine_(seed) {}

  /// In [0, 1), with all 53 bits of a double.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

  /// Standard normal by Box-Muller (one of the pair is enough here).
  double normal() {
    const double nonzero = 1.0 - uniform(); // (0, 1]: log stays finite
    return std::sqrt(-2.0 * std::log(nonzero)) * std::cos(2.0 * kPi * uniform());
  }

private:
  std::mt19937_64 engine_;
};

/// 25 -> "25", 0.0015 -> "0.0015": for names and descriptions.
std::string shortNumber(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

void requireRatio(double ratio) {
  if (!(ratio >= 1.0) || !std::isfinite(ratio))
    throw std::invalid_argument("density ratio must be finite and at least 1");
}

/// Keeps drawing area-uniform candidates (`draw`) and keeps each with
/// probability `acceptance(p)` in [0, 1] until `points` are kept.
template <typename Draw, typename Acceptance>
pcl::PointCloud<pcl::PointXYZ> sampleByRejection(std::size_t points, PortableRandom &random,
                                                 Draw draw, Acceptance acceptance) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  cloud.reserve(points);
  while (cloud.size() < points) {
    const Eigen::Vector3d candidate = draw();
    if (random.uniform() < acceptance(candidate))
      cloud.push_back(pcl::PointXYZ(static_cast<float>(candidate.x()),
                                    static_cast<float>(candidate.y()),
                                    static_cast<float>(candidate.z())));
  }
  return cloud;
}

/// A point of the unit sphere with the given z, at a uniform longitude.
Eigen::Vector3d unitSpherePointAtHeight(double z, PortableRandom &random) {
  const double longitude = 2.0 * kPi * random.uniform();
  const double radius = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {radius * std::cos(longitude), radius * std::sin(longitude), z};
}

/// The part z >= lowest_z of the unit sphere, density ∝ exp(log_density_per_z * z).
pcl::PointCloud<pcl::PointXYZ> sphereZoneWithDensityGradient(std::size_t points, double lowest_z,
                                                             double log_density_per_z,
                                                             std::uint64_t seed) {
  PortableRandom random(seed);
  const double densest_z = log_density_per_z > 0 ? 1.0 : lowest_z;
  // Archimedes: z uniform is area-uniform on the sphere.
  return sampleByRejection(
      points, random,
      [&] {
        return unitSpherePointAtHeight(lowest_z + (1.0 - lowest_z) * random.uniform(), random);
      },
      [&](const Eigen::Vector3d &p) { return std::exp(log_density_per_z * (p.z() - densest_z)); });
}

/// Share of the dense level at angle θ of the torus bands: 1 inside a dense
/// band, 0 inside a sparse one, a smoothstep across each border.
double denseBandLevel(double theta, int bands) {
  const double width = 2.0 * kPi / bands;
  const double wrapped = std::fmod(std::fmod(theta, 2.0 * kPi) + 2.0 * kPi, 2.0 * kPi);
  const int band = std::min(bands - 1, static_cast<int>(wrapped / width));
  const double into_band = wrapped - band * width;
  const double to_border = std::min(into_band, width - into_band);
  const double t = std::min(1.0, to_border / kTorusBandTransition);
  const double own = 0.5 + 0.5 * t * t * (3.0 - 2.0 * t); // 1/2 at the border
  return band % 2 == 0 ? own : 1.0 - own;
}

/// Entry distance of a ray into an axis-aligned box (slab method), or
/// infinity when it misses.
float rayEntersBox(const Eigen::Vector3f &origin, const Eigen::Vector3f &direction,
                   const Eigen::Vector3f &box_min, const Eigen::Vector3f &box_max) {
  float enter = 0, leave = std::numeric_limits<float>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    if (direction[axis] == 0) {
      if (origin[axis] < box_min[axis] || origin[axis] > box_max[axis])
        return std::numeric_limits<float>::infinity();
      continue;
    }
    float near = (box_min[axis] - origin[axis]) / direction[axis];
    float far = (box_max[axis] - origin[axis]) / direction[axis];
    if (near > far)
      std::swap(near, far);
    enter = std::max(enter, near);
    leave = std::min(leave, far);
  }
  return enter <= leave ? enter : std::numeric_limits<float>::infinity();
}

} // namespace

SyntheticCloud sphereWithDensityGradient(std::size_t points, double ratio, std::uint64_t seed) {
  requireRatio(ratio);
  SyntheticCloud result;
  // ratio^((z + 1) / 2) = sqrt(ratio) · exp(log(ratio) / 2 · z)
  result.cloud = sphereZoneWithDensityGradient(points, -1.0, std::log(ratio) / 2.0, seed);
  result.name = "sphere_gradient_" + shortNumber(ratio);
  result.density_law = "unit sphere, density ∝ ratio^((z+1)/2), ratio " + shortNumber(ratio);
  result.truth = {1, 0, 2, true};
  return result;
}

SyntheticCloud torusWithDensityBands(std::size_t points, double ratio, int bands,
                                     std::uint64_t seed) {
  requireRatio(ratio);
  if (bands < 2 || bands % 2 != 0)
    throw std::invalid_argument("torus bands must be an even number of at least 2");
  constexpr double major = 1.0, minor = 0.35;
  PortableRandom random(seed);
  const double log_ratio = std::log(ratio);
  auto draw = [&]() -> Eigen::Vector3d {
    const double theta = 2.0 * kPi * random.uniform();
    // The area element grows with the distance from the axis, major + minor cos φ.
    double phi = 0;
    do
      phi = 2.0 * kPi * random.uniform();
    while (random.uniform() * (major + minor) >= major + minor * std::cos(phi));
    const double from_axis = major + minor * std::cos(phi);
    return {from_axis * std::cos(theta), from_axis * std::sin(theta), minor * std::sin(phi)};
  };
  SyntheticCloud result;
  result.cloud = sampleByRejection(points, random, draw, [&](const Eigen::Vector3d &p) {
    return std::exp(log_ratio * (denseBandLevel(std::atan2(p.y(), p.x()), bands) - 1.0));
  });
  result.name = "torus_bands_" + shortNumber(ratio);
  result.density_law = "torus R 1 r 0.35, " + std::to_string(bands) +
                       " bands around z alternating density ratio and 1, ratio " +
                       shortNumber(ratio);
  result.truth = {1, 0, 0, true};
  return result;
}

SyntheticCloud annulusWithDensityGradient(std::size_t points, double ratio, std::uint64_t seed,
                                          double out_of_plane_noise) {
  requireRatio(ratio);
  PortableRandom random(seed);
  const double log_ratio = std::log(ratio);
  constexpr double inner_squared = kAnnulusInnerRadius * kAnnulusInnerRadius;
  constexpr double outer_squared = kAnnulusOuterRadius * kAnnulusOuterRadius;
  auto draw = [&]() -> Eigen::Vector3d {
    // The radius squared uniform between the two radii squared is area-uniform.
    const double radius =
        std::sqrt(inner_squared + random.uniform() * (outer_squared - inner_squared));
    const double angle = 2.0 * kPi * random.uniform();
    return {radius * std::cos(angle), radius * std::sin(angle), 0.0};
  };
  SyntheticCloud result;
  result.cloud = sampleByRejection(points, random, draw, [&](const Eigen::Vector3d &p) {
    return std::exp(log_ratio * (p.x() - 1.0) / 2.0);
  });
  // Drawn after the positions, so both versions have the same x and y.
  if (out_of_plane_noise > 0)
    for (pcl::PointXYZ &p : result.cloud)
      p.z = static_cast<float>(out_of_plane_noise * random.normal());
  result.name = "annulus_gradient_" + shortNumber(ratio) + (out_of_plane_noise > 0 ? "_noisy" : "");
  result.density_law =
      "annulus radii 0.35-1 in z = 0, density ∝ ratio^((x+1)/2), ratio " + shortNumber(ratio) +
      (out_of_plane_noise > 0 ? ", z noise sigma " + shortNumber(out_of_plane_noise)
                              : std::string());
  result.truth = {1, 2, 0, true};
  return result;
}

SyntheticCloud hemisphereWithDensityGradient(std::size_t points, double ratio, std::uint64_t seed) {
  requireRatio(ratio);
  SyntheticCloud result;
  // ratio^(1 - z) = ratio · exp(-log(ratio) · z)
  result.cloud = sphereZoneWithDensityGradient(points, 0.0, -std::log(ratio), seed);
  result.name = "hemisphere_gradient_" + shortNumber(ratio);
  result.density_law = "unit hemisphere z >= 0, density ∝ ratio^(1-z), ratio " + shortNumber(ratio);
  result.truth = {1, 1, 1, true};
  return result;
}

SyntheticScan oneViewScanOfBoxOnPlane(int width, int height, std::uint64_t seed,
                                      double range_noise_at_one_metre) {
  if (width < 2 || height < 2)
    throw std::invalid_argument("the scan needs at least 2 x 2 pixels");
  SyntheticScan scan;
  const BoxOnPlaneScene &scene = scan.scene;
  const Eigen::Vector3f forward = (scene.look_at - scene.sensor).normalized();
  const Eigen::Vector3f right = forward.cross(Eigen::Vector3f::UnitZ()).normalized();
  const Eigen::Vector3f down = forward.cross(right);
  Eigen::Matrix3f sensor_to_cloud;
  sensor_to_cloud << right, down, forward;
  const float focal = 0.5f * static_cast<float>(width) /
                      std::tan(0.5f * scene.horizontal_fov_deg * static_cast<float>(kPi) / 180);
  const float centre_u = 0.5f * static_cast<float>(width);
  const float centre_v = 0.5f * static_cast<float>(height);

  PortableRandom random(seed);
  const float missing = std::numeric_limits<float>::quiet_NaN();
  pcl::PointCloud<pcl::PointXYZ> &cloud = scan.cloud;
  cloud.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  cloud.width = static_cast<std::uint32_t>(width);
  cloud.height = static_cast<std::uint32_t>(height);
  cloud.is_dense = false;
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      const Eigen::Vector3f ray =
          sensor_to_cloud * Eigen::Vector3f((static_cast<float>(u) + 0.5f - centre_u) / focal,
                                            (static_cast<float>(v) + 0.5f - centre_v) / focal, 1)
                                .normalized();
      float range = rayEntersBox(scene.sensor, ray, scene.box_min, scene.box_max);
      if (ray.z() < 0)
        range = std::min(range, (scene.ground_z - scene.sensor.z()) / ray.z());
      pcl::PointXYZ &point = cloud.at(u, v);
      if (!(range <= scene.max_range)) {
        point = pcl::PointXYZ(missing, missing, missing);
        continue;
      }
      if (range_noise_at_one_metre > 0)
        range += static_cast<float>(range_noise_at_one_metre * range * range * random.normal());
      const Eigen::Vector3f hit = scene.sensor + range * ray;
      point = pcl::PointXYZ(hit.x(), hit.y(), hit.z());
    }
  cloud.sensor_origin_ = Eigen::Vector4f(scene.sensor.x(), scene.sensor.y(), scene.sensor.z(), 0);
  cloud.sensor_orientation_ = Eigen::Quaternionf(sensor_to_cloud);

  scan.name = "box_scan_" + std::to_string(width) + "x" + std::to_string(height) +
              (range_noise_at_one_metre > 0 ? "_noisy" : "");
  scan.density_law =
      "depth frame, pixels uniform in angle: density ∝ cos(incidence) / range²" +
      (range_noise_at_one_metre > 0 ? std::string(", range noise sigma ") +
                                          shortNumber(range_noise_at_one_metre) + " * range²"
                                    : std::string());
  scan.truth = {1, 2, 0, true};
  scan.focal_length_px = focal;
  scan.range_noise_at_one_metre = range_noise_at_one_metre;
  return scan;
}

std::vector<SyntheticCloud> syntheticClouds(std::uint64_t seed, int scan_width, int scan_height) {
  // Kinect-like: about 2 mm at 1 m, 2 cm at 3.5 m.
  constexpr double kinect_range_noise = 0.0015;
  return {sphereWithDensityGradient(8000, 25, seed),
          torusWithDensityBands(10000, 9, 6, seed),
          annulusWithDensityGradient(6000, 10, seed),
          annulusWithDensityGradient(6000, 10, seed, 2e-4),
          hemisphereWithDensityGradient(6000, 16, seed),
          oneViewScanOfBoxOnPlane(scan_width, scan_height, seed),
          oneViewScanOfBoxOnPlane(scan_width, scan_height, seed, kinect_range_noise)};
}

} // namespace pcl_ms_tools
