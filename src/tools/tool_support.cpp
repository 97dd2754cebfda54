// SPDX-License-Identifier: GPL-3.0-or-later
#include "tool_support.h"

#include <pcl/conversions.h>

#include <cmath>
#include <cstdio>
#include <exception>

namespace pcl_ms_tools {

int fail(int code, const std::string &reason) {
  std::fflush(stdout);
  std::fprintf(stderr, "error: %s\n", reason.c_str());
  return code;
}

int runGuarded(int (*run)(int, char **), int argc, char **argv, int failure_code) {
  try {
    return run(argc, argv);
  } catch (const std::exception &exception) {
    return fail(failure_code, std::string("unexpected failure: ") + exception.what());
  }
}

std::size_t finitePoints(const pcl::PCLPointCloud2 &cloud, pcl::PointCloud<pcl::PointXYZ> &points) {
  pcl::PointCloud<pcl::PointXYZ> all;
  {
    SilencePclMessages silence; // fields other than x, y, z are expected to be missing
    pcl::fromPCLPointCloud2(cloud, all);
  }
  points.clear();
  points.reserve(all.size());
  for (const pcl::PointXYZ &p : all)
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
      points.push_back(p);
  return all.size() - points.size();
}

std::vector<Eigen::Vector3d> positions(const pcl::PointCloud<pcl::PointXYZ> &points) {
  std::vector<Eigen::Vector3d> result;
  result.reserve(points.size());
  for (const pcl::PointXYZ &p : points)
    result.emplace_back(p.x, p.y, p.z);
  return result;
}

pcl_ms::PointView pointView(const pcl::PointCloud<pcl::PointXYZ> &points) {
  pcl_ms::PointView view;
  view.xyz = points.empty() ? nullptr : &points[0].x;
  view.size = points.size();
  view.stride = sizeof(pcl::PointXYZ);
  return view;
}

} // namespace pcl_ms_tools

namespace pcl_ms_tools {

std::optional<std::array<double, 3>> sensorViewpoint(const pcl::PCLPointCloud2 &cloud,
                                                     const Eigen::Vector4f &sensor_origin) {
  if (cloud.height <= 1 && sensor_origin.head<3>() == Eigen::Vector3f::Zero())
    return std::nullopt;
  return std::array<double, 3>{sensor_origin[0], sensor_origin[1], sensor_origin[2]};
}

} // namespace pcl_ms_tools
