// SPDX-License-Identifier: GPL-3.0-or-later
#include "normal_estimation.h"

#include <pcl_ms/io.h>

#include <pcl/common/io.h>
#include <pcl/common/point_tests.h>
#include <pcl/conversions.h>
#include <pcl/features/normal_3d.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <cmath>
#include <limits>

namespace pcl_ms_tools {

bool estimateNormals(pcl::PCLPointCloud2 &cloud, int neighbours,
                     const std::optional<std::array<double, 3>> &viewpoint, std::string &error) {
  if (neighbours < 3) {
    error =
        "normal estimation needs at least 3 neighbours (got " + std::to_string(neighbours) + ")";
    return false;
  }
  if (pcl_ms::hasNormals(cloud)) {
    error = "the cloud already has normals: use -normals to use them";
    return false;
  }
  auto points = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::fromPCLPointCloud2(cloud, *points);
  // The k-d tree takes only points with a position; the others keep NaN.
  auto finite = pcl::make_shared<pcl::Indices>();
  for (std::size_t i = 0; i < points->size(); ++i)
    if (pcl::isFinite((*points)[i]))
      finite->push_back(static_cast<pcl::index_t>(i));
  pcl::PointCloud<pcl::Normal> normals;
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
  estimation.setInputCloud(points);
  estimation.setIndices(finite);
  estimation.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  estimation.setKSearch(neighbours);
  if (viewpoint)
    estimation.setViewPoint(static_cast<float>((*viewpoint)[0]),
                            static_cast<float>((*viewpoint)[1]),
                            static_cast<float>((*viewpoint)[2]));
  pcl::PointCloud<pcl::Normal> estimated;
  estimation.compute(estimated);
  // Estimated normals come in the order of `finite`; place them at their points.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  normals.resize(points->size(), pcl::Normal(nan, nan, nan, nan));
  normals.width = points->width;
  normals.height = points->height;
  for (std::size_t k = 0; k < finite->size(); ++k)
    normals[static_cast<std::size_t>((*finite)[k])] = estimated[k];
  pcl::PCLPointCloud2 normal_fields, joined;
  pcl::toPCLPointCloud2(normals, normal_fields);
  if (!pcl::concatenateFields(cloud, normal_fields, joined)) {
    error = "could not add the estimated normals to the cloud";
    return false;
  }
  cloud = std::move(joined);
  return true;
}

} // namespace pcl_ms_tools
