// SPDX-License-Identifier: GPL-3.0-or-later
// Helpers for the core's tests, without PCL: bundled data read through the
// PCL-free mesh reader, small hand-made clouds and the mesh checks.
#pragma once

#include <pcl_ms/mesh_file.h>
#include <pcl_ms/mesh_quality.h>
#include <pcl_ms/reconstruct.h>

#include <gtest/gtest.h>

#include <Eigen/Core>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace pcl_ms_test {

inline std::string dataPath(const std::string &name) {
  return std::string(PCL_MS_DATA_DIR) + "/" + name;
}

struct ReferenceMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
};

inline const ReferenceMesh &bunnyReference() {
  static const ReferenceMesh mesh = [] {
    ReferenceMesh loaded;
    std::string error;
    if (!pcl_ms::loadMesh(dataPath("bun_zipper.ply"), loaded.vertices, loaded.triangles, error))
      throw std::runtime_error(error);
    return loaded;
  }();
  return mesh;
}

/// The bunny's points as x, y, z floats: bun_zipper.ply's vertices hold the
/// same float values, in the same order, as data/bunny.pcd.
inline std::vector<float> bunnyCoordinates() {
  std::vector<float> xyz;
  for (const Eigen::Vector3d &vertex : bunnyReference().vertices)
    for (int k = 0; k < 3; ++k)
      xyz.push_back(static_cast<float>(vertex[k]));
  return xyz;
}

inline std::vector<Eigen::Vector3d> positions(const std::vector<float> &xyz) {
  std::vector<Eigen::Vector3d> result;
  for (std::size_t i = 0; i + 2 < xyz.size(); i += 3)
    result.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
  return result;
}

inline pcl_ms::PointView viewOf(const std::vector<float> &xyz) {
  pcl_ms::PointView view;
  view.xyz = xyz.data();
  view.size = xyz.size() / 3;
  return view;
}

/// n points on a unit sphere, evenly spread (Fibonacci lattice).
inline std::vector<float> fibonacciSphere(int n, double radius = 1.0,
                                          Eigen::Vector3d centre = Eigen::Vector3d::Zero()) {
  std::vector<float> xyz;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - y * y), phi = golden * i;
    xyz.push_back(static_cast<float>(centre.x() + radius * r * std::cos(phi)));
    xyz.push_back(static_cast<float>(centre.y() + radius * y));
    xyz.push_back(static_cast<float>(centre.z() + radius * r * std::sin(phi)));
  }
  return xyz;
}

/// The manifold checks every reconstruction must pass.
inline void expectCleanManifold(const pcl_ms::MeshTopologyReport &report) {
  EXPECT_EQ(report.non_manifold_edges, 0u);
  EXPECT_EQ(report.non_manifold_vertices, 0u);
  EXPECT_EQ(report.degenerate_triangles, 0u);
  EXPECT_EQ(report.duplicate_triangles, 0u);
  EXPECT_EQ(report.invalid_triangles, 0u);
}

/// A strip of `segments` quads around a circle whose ends are glued with a
/// half twist.
inline void moebiusBand(int segments, double half_width, std::vector<Eigen::Vector3d> &points,
                        std::vector<pcl_ms::Triangle> &triangles) {
  for (int i = 0; i < segments; ++i) {
    const double angle = 2 * M_PI * i / segments, twist = angle / 2;
    for (double side : {-half_width, half_width}) {
      const double r = 1 + side * std::cos(twist);
      points.emplace_back(r * std::cos(angle), r * std::sin(angle), side * std::sin(twist));
    }
  }
  for (int i = 0; i < segments; ++i) {
    const pcl_ms::VertexIndex a = 2 * i, b = 2 * i + 1;
    pcl_ms::VertexIndex c = 2 * ((i + 1) % segments), d = c + 1;
    if (i == segments - 1)
      std::swap(c, d); // the half twist
    triangles.push_back({a, b, d});
    triangles.push_back({a, d, c});
  }
}

} // namespace pcl_ms_test
