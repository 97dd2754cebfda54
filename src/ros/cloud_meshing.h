// SPDX-License-Identifier: GPL-3.0-or-later
// The ROS-free half of the ROS nodes. A sensor_msgs/PointCloud2 (ROS 1 and
// ROS 2 alike) maps one to one onto pcl::PCLPointCloud2; this layer checks
// such a cloud, meshes it with pcl::MedialScaffoldReconstruction and turns
// the mesh into the point and colour arrays of RViz markers. The nodelet only
// copies messages in and out, so a ROS 2 component is a small file too.
#pragma once

#include <pcl/PCLPointCloud2.h>
#include <pcl/PCLPointField.h>
#include <pcl/Vertices.h>
#include <pcl_ms/types.h>

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace pcl_ms {
namespace ros_bridge {

/// The point type a cloud is converted to for meshing. Only positions (and
/// normals when asked for) matter: the published mesh keeps the message's
/// own cloud, so colour, intensity and every other field ride along anyway.
enum class MeshingPointType { xyz, xyz_normal };

/// PointXYZ unless normals are wanted and the cloud has normal_x/y/z.
MeshingPointType choosePointType(const std::vector<pcl::PCLPointField> &fields, bool use_normals);

/// True when the fields include normal_x, normal_y and normal_z, each
/// FLOAT32 or FLOAT64.
bool hasNormalFields(const std::vector<pcl::PCLPointField> &fields);

/// Empty when the cloud's layout can be read, else a one-line reason: no
/// points, x/y/z missing or neither FLOAT32 nor FLOAT64 (read as float), a
/// field outside the point, rows or data shorter than the sizes claim,
/// big-endian data.
std::string checkCloudLayout(const pcl::PCLPointCloud2 &cloud);

/// What meshing one cloud gave.
struct MeshingOutcome {
  std::string error;                   ///< empty on success, else the reason (layout or library)
  std::string warning;                 ///< e.g. normals asked for but absent; meshing went on
  std::vector<pcl::Vertices> polygons; ///< triangles, indices into the cloud
  std::vector<pcl::Vertices> boundary_loops; ///< indices into the cloud
  std::size_t finite_points = 0;             ///< points that were not NaN/Inf
  double median_circumradius = 0;            ///< d_med, the mesh's length scale
  double conversion_seconds = 0;             ///< PCLPointCloud2 to the typed cloud
  double library_seconds = 0;                ///< pcl::MedialScaffoldReconstruction::reconstruct
};

/// Checks, converts and meshes one cloud with the library's parameters
/// (pcl::MedialScaffoldReconstruction::setParameters). Never throws: every
/// failure, including the library's own reason, comes back in
/// MeshingOutcome::error.
MeshingOutcome meshCloud(const pcl::PCLPointCloud2 &cloud, const pcl_ms::Parameters &parameters);

/// Points (and optional per-point colours) of one RViz marker.
struct MarkerGeometry {
  std::vector<std::array<float, 3>> points;
  /// One RGBA colour in [0, 1] per point, or empty: use the marker's colour.
  std::vector<std::array<float, 4>> colors;
};

/// TRIANGLE_LIST geometry: three points per triangle, coloured from the
/// cloud's rgb or rgba field when it has one. Polygons that are not
/// triangles, index outside the cloud or touch a non-finite point are left
/// out (the library makes none, but the message could come from anywhere).
MarkerGeometry triangleListGeometry(const pcl::PCLPointCloud2 &cloud,
                                    const std::vector<pcl::Vertices> &polygons);

/// LINE_LIST geometry: two points per boundary edge, each loop closed.
MarkerGeometry boundaryLineGeometry(const pcl::PCLPointCloud2 &cloud,
                                    const std::vector<pcl::Vertices> &loops);

} // namespace ros_bridge
} // namespace pcl_ms
