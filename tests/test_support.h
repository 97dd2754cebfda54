// SPDX-License-Identifier: GPL-3.0-or-later
// Helpers shared by the tests that use PCL: the core's helpers plus clouds
// read through the tools' loader and views of PCL clouds.
#pragma once

#include "core/core_test_support.h"

#include <pcl_ms/io.h>

#include <pcl/conversions.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace pcl_ms_test {

inline pcl::PointCloud<pcl::PointXYZ>::Ptr loadXYZ(const std::string &name) {
  pcl::PCLPointCloud2 blob;
  std::string error;
  if (!pcl_ms::loadPointCloud(dataPath(name), blob, error))
    throw std::runtime_error(error);
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::fromPCLPointCloud2(blob, *cloud);
  return cloud;
}

template <typename PointT>
std::vector<Eigen::Vector3d> positions(const pcl::PointCloud<PointT> &cloud) {
  std::vector<Eigen::Vector3d> result;
  for (const auto &p : cloud)
    result.emplace_back(p.x, p.y, p.z);
  return result;
}

template <typename PointT> pcl_ms::PointView viewOf(const pcl::PointCloud<PointT> &cloud) {
  pcl_ms::PointView view;
  view.xyz = &cloud[0].x;
  view.size = cloud.size();
  view.stride = sizeof(PointT);
  return view;
}

/// Loads a cloud and expects failure with a one-line reason that names the
/// file; returns the reason.
inline std::string expectCloudFailure(const std::string &file) {
  pcl::PCLPointCloud2 cloud;
  std::string error;
  EXPECT_FALSE(pcl_ms::loadPointCloud(file, cloud, error)) << file;
  EXPECT_NE(error.find(file), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  EXPECT_EQ(cloud.width * cloud.height, 0u);
  return error;
}

/// The same for a mesh.
inline std::string expectMeshFailure(const std::string &file) {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  std::string error;
  EXPECT_FALSE(pcl_ms::loadMesh(file, vertices, triangles, error)) << file;
  EXPECT_NE(error.find(file), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  EXPECT_TRUE(vertices.empty());
  EXPECT_TRUE(triangles.empty());
  return error;
}

} // namespace pcl_ms_test
