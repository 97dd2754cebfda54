// SPDX-License-Identifier: GPL-3.0-or-later
//
// Uniform random points on a triangle mesh, for benchmarks that need clouds
// larger than the bundled data, with a known surface under them.
#pragma once

#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace pcl_ms_tools {

/// `count` points uniform on the surface: triangles drawn in proportion to
/// their area, points uniform inside them. Same seed, same points.
std::vector<Eigen::Vector3f> sampleSurface(const std::vector<Eigen::Vector3d> &vertices,
                                           const std::vector<pcl_ms::Triangle> &triangles,
                                           std::size_t count, std::uint32_t seed);

} // namespace pcl_ms_tools
