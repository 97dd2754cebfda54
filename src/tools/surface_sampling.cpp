// SPDX-License-Identifier: GPL-3.0-or-later
#include "surface_sampling.h"

#include <algorithm>
#include <random>

namespace pcl_ms_tools {

std::vector<Eigen::Vector3f> sampleSurface(const std::vector<Eigen::Vector3d> &vertices,
                                           const std::vector<pcl_ms::Triangle> &triangles,
                                           std::size_t count, std::uint32_t seed) {
  std::vector<Eigen::Vector3f> points;
  if (triangles.empty())
    return points;
  std::vector<double> cumulative_area(triangles.size());
  double total = 0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Eigen::Vector3d &a = vertices[triangles[t][0]];
    total += 0.5 * (vertices[triangles[t][1]] - a).cross(vertices[triangles[t][2]] - a).norm();
    cumulative_area[t] = total;
  }
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> area(0.0, total), unit(0.0, 1.0);
  points.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const auto chosen =
        std::upper_bound(cumulative_area.begin(), cumulative_area.end(), area(random)) -
        cumulative_area.begin();
    const pcl_ms::Triangle &triangle =
        triangles[std::min<std::size_t>(static_cast<std::size_t>(chosen), triangles.size() - 1)];
    double u = unit(random), v = unit(random);
    if (u + v > 1) { // fold the far half of the square back onto the triangle
      u = 1 - u;
      v = 1 - v;
    }
    const Eigen::Vector3d &a = vertices[triangle[0]];
    points.push_back(
        (a + u * (vertices[triangle[1]] - a) + v * (vertices[triangle[2]] - a)).cast<float>());
  }
  return points;
}

} // namespace pcl_ms_tools
