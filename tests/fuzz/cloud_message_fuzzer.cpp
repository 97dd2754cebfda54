// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the ROS nodes' ROS-free half (src/ros/cloud_meshing.h)
// on a sensor_msgs/PointCloud2 as pcl::PCLPointCloud2 with any header: fields
// of any name, type, offset and count (repeated ones too), steps and sizes
// that disagree with each other and with the data, either byte order. A
// message must be refused with a reason or meshed with polygons and loops
// over its finite points, and marker geometry built from it and any polygons
// must read inside the data.
#include "cloud_meshing.h"
#include "fuzz_bytes.h"

#include <pcl/PCLPointCloud2.h>

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace {

/// At most this many points a message: meshing is the slow part.
constexpr std::uint64_t max_message_points = 128;

} // namespace

namespace pcl_ms_fuzz {

/// The target's body (see PCL_MS_FUZZ_TARGET).
inline int cloudMessageOneInput(const std::uint8_t *data, std::size_t size) {
  ByteReader bytes(data, size);
  static const char *const names[] = {"x",        "y",   "z",    "normal_x",  "normal_y",
                                      "normal_z", "rgb", "rgba", "intensity", ""};
  constexpr int name_count = sizeof names / sizeof names[0];
  pcl::PCLPointCloud2 cloud;
  const std::uint8_t options = bytes.byte();
  cloud.is_bigendian = (options & 1) != 0;
  cloud.is_dense = (options & 2) != 0;
  pcl_ms::Parameters parameters;
  parameters.use_normals = (options & 4) != 0;
  parameters.fill_holes_max_edges = (options & 8) ? 0 : 8;
  cloud.width = bytes.byte() % 16;
  cloud.height = bytes.byte() % 16;
  if (std::uint64_t{cloud.width} * cloud.height > max_message_points)
    return 0;
  cloud.point_step = bytes.byte();
  cloud.row_step = bytes.word();
  const int field_count = bytes.byte() % 12;
  for (int i = 0; i < field_count; ++i) {
    pcl::PCLPointField field;
    field.name = names[bytes.byte() % name_count];
    field.datatype = bytes.byte() % 10; // 0 and 9 are no PointField type
    field.offset = bytes.byte();
    field.count = bytes.byte() % 4;
    cloud.fields.push_back(field);
  }
  const std::vector<std::uint8_t> payload = bytes.rest();
  cloud.data.assign(payload.begin(), payload.end());

  const std::size_t points = std::size_t{cloud.width} * cloud.height;
  const pcl_ms::ros_bridge::MeshingOutcome outcome =
      pcl_ms::ros_bridge::meshCloud(cloud, parameters);
  if (outcome.error.empty()) {
    for (const auto *list : {&outcome.polygons, &outcome.boundary_loops})
      for (const pcl::Vertices &polygon : *list)
        for (std::uint32_t v : polygon.vertices)
          if (v >= points)
            broken("polygons and loops index the cloud");
  } else if (!outcome.polygons.empty()) {
    broken("a refused cloud has no mesh");
  }
  // The marker builders take polygons from anywhere: the mesh's, and some
  // made of the message's own bytes (any index, any size).
  std::vector<pcl::Vertices> arbitrary(cloud.data.size() / 8);
  for (std::size_t i = 0; i < arbitrary.size(); ++i)
    for (std::size_t k = 0; k < 1 + i % 4; ++k)
      arbitrary[i].vertices.push_back(cloud.data[(8 * i + k) % cloud.data.size()] % 160);
  for (const std::vector<pcl::Vertices> *list : {&outcome.polygons, &std::as_const(arbitrary)}) {
    const pcl_ms::ros_bridge::MarkerGeometry triangles =
        pcl_ms::ros_bridge::triangleListGeometry(cloud, *list);
    if (triangles.points.size() % 3 != 0 ||
        (!triangles.colors.empty() && triangles.colors.size() != triangles.points.size()))
      broken("a triangle list has three points a triangle and a colour a point");
    for (const auto &point : triangles.points)
      if (!std::isfinite(point[0]) || !std::isfinite(point[1]) || !std::isfinite(point[2]))
        broken("marker points are finite");
  }
  const pcl_ms::ros_bridge::MarkerGeometry lines =
      pcl_ms::ros_bridge::boundaryLineGeometry(cloud, outcome.boundary_loops);
  if (lines.points.size() % 2 != 0)
    broken("a line list has two points a line");
  pcl_ms::ros_bridge::boundaryLineGeometry(cloud, arbitrary);
  return 0;
}

} // namespace pcl_ms_fuzz

PCL_MS_FUZZ_TARGET(pcl_ms_fuzz::cloudMessageOneInput)
