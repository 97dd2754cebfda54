// SPDX-License-Identifier: GPL-3.0-or-later
#include "finite_vertices.h"

#include <pcl/PCLPointField.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

namespace pcl_ms_tools {
namespace {

const pcl::PCLPointField *floatField(const pcl::PCLPointCloud2 &cloud, const std::string &name) {
  for (const pcl::PCLPointField &field : cloud.fields)
    if (field.name == name && field.datatype == pcl::PCLPointField::FLOAT32 &&
        field.offset + sizeof(float) <= cloud.point_step)
      return &field;
  return nullptr;
}

} // namespace

std::size_t dropNonFiniteVertices(pcl::PolygonMesh &mesh) {
  pcl::PCLPointCloud2 &cloud = mesh.cloud;
  const pcl::PCLPointField *axes[3] = {floatField(cloud, "x"), floatField(cloud, "y"),
                                       floatField(cloud, "z")};
  const std::size_t points = std::size_t{cloud.width} * cloud.height;
  if (!axes[0] || !axes[1] || !axes[2] || cloud.data.size() < points * cloud.point_step)
    return 0;
  std::vector<bool> used(points, false);
  for (const pcl::Vertices &polygon : mesh.polygons)
    for (const auto corner : polygon.vertices) {
      if (corner < 0 || static_cast<std::size_t>(corner) >= points)
        return 0; // not a mesh of this cloud: saving will say so
      used[static_cast<std::size_t>(corner)] = true;
    }
  constexpr std::uint32_t dropped = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> new_index(points, dropped);
  std::uint32_t kept = 0;
  bool all_finite = true;
  for (std::size_t i = 0; i < points; ++i) {
    const std::uint8_t *point = cloud.data.data() + i * cloud.point_step;
    bool finite = true;
    for (const pcl::PCLPointField *axis : axes) {
      float value;
      std::memcpy(&value, point + axis->offset, sizeof value);
      finite = finite && std::isfinite(value);
    }
    if (finite || used[i])
      new_index[i] = kept++;
    all_finite = all_finite && (finite || !used[i]);
  }
  if (kept == points)
    return 0;
  // Rows move only towards the front, so the copy can work in place.
  for (std::size_t i = 0; i < points; ++i)
    if (new_index[i] != dropped && new_index[i] != i)
      std::memmove(cloud.data.data() + std::size_t{new_index[i]} * cloud.point_step,
                   cloud.data.data() + i * cloud.point_step, cloud.point_step);
  cloud.data.resize(std::size_t{kept} * cloud.point_step);
  cloud.width = kept;
  cloud.height = 1;
  cloud.row_step = kept * cloud.point_step;
  cloud.is_dense = all_finite;
  for (pcl::Vertices &polygon : mesh.polygons)
    for (auto &corner : polygon.vertices)
      corner = static_cast<std::remove_reference_t<decltype(corner)>>(
          new_index[static_cast<std::size_t>(corner)]);
  return points - kept;
}

} // namespace pcl_ms_tools
