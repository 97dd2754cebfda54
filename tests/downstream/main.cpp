// SPDX-License-Identifier: GPL-3.0-or-later
// Downstream smoke test: meshes a Fibonacci sphere with the installed
// pcl::MedialScaffoldReconstruction. Exits 0 only if the mesh has polygons
// and every polygon indexes the input cloud.
#include <pcl_ms/medial_scaffold_reconstruction.h>

#include <pcl/PolygonMesh.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstddef>
#include <iostream>

int main() {
  constexpr std::size_t kPoints = 400;
  const double pi = std::acos(-1.0);
  const double golden_angle = pi * (3.0 - std::sqrt(5.0));

  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(kPoints);
  for (std::size_t i = 0; i < kPoints; ++i) {
    const double z = 1.0 - 2.0 * (static_cast<double>(i) + 0.5) / kPoints;
    const double r = std::sqrt(1.0 - z * z);
    const double phi = golden_angle * static_cast<double>(i);
    cloud->push_back(pcl::PointXYZ(static_cast<float>(r * std::cos(phi)),
                                   static_cast<float>(r * std::sin(phi)), static_cast<float>(z)));
  }

  pcl::MedialScaffoldReconstruction<pcl::PointXYZ> msr;
  msr.setInputCloud(cloud);
  pcl::PolygonMesh mesh;
  msr.reconstruct(mesh);

  const std::size_t vertices = static_cast<std::size_t>(mesh.cloud.width) * mesh.cloud.height;
  std::cout << "pcl_ms downstream: " << cloud->size() << " points -> " << mesh.polygons.size()
            << " polygons over " << vertices << " vertices\n";
  if (mesh.polygons.empty()) {
    std::cerr << "error: the mesh has no polygons\n";
    return 1;
  }
  for (const auto &polygon : mesh.polygons)
    for (const auto index : polygon.vertices)
      if (index < 0 || static_cast<std::size_t>(index) >= vertices) {
        std::cerr << "error: polygon index " << index << " out of range\n";
        return 1;
      }
  return 0;
}
