// SPDX-License-Identifier: GPL-3.0-or-later
//
// Clouds whose topology is known and whose density is strongly non-uniform,
// for the tests and measurements of issue 11 (local scale). Every generator
// is deterministic: the same arguments give the same points with every
// standard library, because the random numbers are computed from the raw
// output of std::mt19937_64 (fully specified by the standard) rather than by
// the standard library's distributions (whose algorithms are not).
//
// The surface generators sample by rejection: a candidate is drawn uniformly
// by area on the surface and kept with probability density(p) / max density,
// until exactly `points` are kept. The expected number of points per unit
// area is therefore proportional to the documented density law, and the
// spacing to its inverse square root.
#pragma once

#include <Eigen/Core>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pcl_ms_tools {

/// The seed of the standard set (syntheticClouds) and of the generators'
/// defaults.
constexpr std::uint64_t kSyntheticSeed = 20261130;

/// What a correct reconstruction of the sampled surface has.
struct KnownTopology {
  std::size_t components = 1;
  std::size_t boundary_loops = 0;
  long long euler_characteristic = 2; // V - E + F
  bool orientable = true;
};

struct SyntheticCloud {
  std::string name;        // a file stem, e.g. "sphere_gradient_25"
  std::string density_law; // for people
  pcl::PointCloud<pcl::PointXYZ> cloud;
  KnownTopology truth;
};

/// Unit sphere at the origin. Density per area ∝ ratio^((z + 1) / 2): 1 at
/// the south pole, `ratio` at the north pole, exponential in between (so the
/// log-density grows linearly with z). Truth: 1 component, 0 loops, χ = 2.
SyntheticCloud sphereWithDensityGradient(std::size_t points = 8000, double ratio = 25,
                                         std::uint64_t seed = kSyntheticSeed);

/// Torus around the z axis, major radius 1, minor radius 0.35, cut into
/// `bands` (even, >= 2) equal sectors of the angle θ around the z axis,
/// alternately dense (density `ratio`) and sparse (density 1), the first
/// dense one starting at θ = 0. The log-density changes between the two
/// levels by a smoothstep over ±kTorusBandTransition radians of θ around
/// each sector border, so the full ratio holds inside each band away from
/// its borders. Truth: 1 component, 0 loops, χ = 0.
SyntheticCloud torusWithDensityBands(std::size_t points = 10000, double ratio = 9, int bands = 6,
                                     std::uint64_t seed = kSyntheticSeed);
constexpr double kTorusBandTransition = 0.05;

/// Flat annulus in the plane z = 0, outer radius 1, inner radius 0.35.
/// Density ∝ ratio^((x + 1) / 2): 1 at the left end (x = -1), `ratio` at the
/// right (x = 1). With `out_of_plane_noise` > 0 every z gets Gaussian noise
/// of that standard deviation (2e-4 is 1e-4 of the diameter): near-planar
/// instead of exactly planar. Truth: 1 component, 2 loops, χ = 0.
SyntheticCloud annulusWithDensityGradient(std::size_t points = 6000, double ratio = 10,
                                          std::uint64_t seed = kSyntheticSeed,
                                          double out_of_plane_noise = 0);
constexpr double kAnnulusOuterRadius = 1.0;
constexpr double kAnnulusInnerRadius = 0.35;

/// Upper half (z >= 0) of the unit sphere, open at the rim z = 0. Density ∝
/// ratio^(1 - z): 1 at the pole, `ratio` at the rim. Truth: 1 component,
/// 1 loop, χ = 1.
SyntheticCloud hemisphereWithDensityGradient(std::size_t points = 6000, double ratio = 16,
                                             std::uint64_t seed = kSyntheticSeed);

/// The scene of oneViewScanOfBoxOnPlane, in metres, z up.
struct BoxOnPlaneScene {
  float ground_z = 0;                                            // the plane z = ground_z
  Eigen::Vector3f box_min = Eigen::Vector3f(-0.3f, -0.2f, 0.0f); // axis-aligned box
  Eigen::Vector3f box_max = Eigen::Vector3f(0.3f, 0.2f, 0.4f);
  Eigen::Vector3f sensor = Eigen::Vector3f(-0.8f, -1.6f, 1.4f);
  Eigen::Vector3f look_at = Eigen::Vector3f(0.1f, 0.3f, 0.0f);
  float horizontal_fov_deg = 58; // a Kinect's
  float max_range = 4;           // rays that hit nothing nearer give NaN
};

struct SyntheticScan : SyntheticCloud {
  BoxOnPlaneScene scene;
  float focal_length_px = 0; // square pixels: one pixel spans 1 / focal_length_px radians
  double range_noise_at_one_metre = 0;
};

/// An organized width x height depth frame (row-major, row 0 at the top) of
/// a box standing on a ground plane, seen obliquely from above by a pinhole
/// sensor (BoxOnPlaneScene). Each pixel's ray through its centre is cast
/// against the plane and the box; the nearest hit within max_range is the
/// point, NaN otherwise (the sky and the far ground). The pixels are uniform
/// in angle, so the density per area falls as cos(incidence) / range².
/// With `range_noise_at_one_metre` = σ₁ > 0 each point moves along its ray by
/// Gaussian noise of standard deviation σ₁ · range² (a Kinect's error grows
/// with the square of the range; σ₁ ≈ 0.0015 is typical). The cloud's
/// sensor_origin_ is the sensor position and sensor_orientation_ rotates the
/// sensor's optical frame (x right, y down, z forward) into the cloud's.
///
/// Truth: the visible surface is a height field seen from the sensor, so it
/// is orientable and every triangle of a faithful mesh faces the sensor. The
/// box's far silhouette (its top's far edges and its outer vertical edges)
/// is a depth discontinuity against the ground behind it: no triangle may
/// bridge it. Cut there, the visible ground, the box's top and its two
/// visible sides form one surface with two boundary loops (the frame's
/// border and range limit, and the cut around the box's shadow): 1
/// component, 2 loops, χ = 0. Away from the cut, neighbouring pixels are at
/// most about range / (focal_length_px · cos(incidence)) apart.
SyntheticScan oneViewScanOfBoxOnPlane(int width = 160, int height = 120,
                                      std::uint64_t seed = kSyntheticSeed,
                                      double range_noise_at_one_metre = 0);

/// The standard set written by bench/make_synthetic_clouds: the four surfaces
/// at their default sizes and ratios (the annulus planar and near-planar),
/// and the scan (160 x 120 by default) without and with Kinect-like noise
/// (σ₁ = 0.0015).
std::vector<SyntheticCloud> syntheticClouds(std::uint64_t seed = kSyntheticSeed,
                                            int scan_width = 160, int scan_height = 120);

} // namespace pcl_ms_tools
