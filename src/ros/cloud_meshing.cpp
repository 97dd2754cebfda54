// SPDX-License-Identifier: GPL-3.0-or-later
#include "cloud_meshing.h"

#include <pcl_ms/medial_scaffold_reconstruction.h>

#include "float_coordinates.h"

#include <pcl/PCLPointField.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <sstream>

namespace pcl_ms {
namespace ros_bridge {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

const pcl::PCLPointField *findField(const std::vector<pcl::PCLPointField> &fields,
                                    const std::string &name) {
  for (const pcl::PCLPointField &field : fields)
    if (field.name == name)
      return &field;
  return nullptr;
}

std::size_t datatypeSize(std::uint8_t datatype) {
  switch (datatype) {
  case pcl::PCLPointField::INT8:
  case pcl::PCLPointField::UINT8:
    return 1;
  case pcl::PCLPointField::INT16:
  case pcl::PCLPointField::UINT16:
    return 2;
  case pcl::PCLPointField::INT32:
  case pcl::PCLPointField::UINT32:
  case pcl::PCLPointField::FLOAT32:
    return 4;
  case pcl::PCLPointField::FLOAT64:
    return 8;
  default:
    return 0;
  }
}

// Coordinates and normals come as FLOAT32, or as FLOAT64 read as float (the
// point types hold float), as the file readers do.
bool isFloatField(const pcl::PCLPointField *field) {
  return field && (field->datatype == pcl::PCLPointField::FLOAT32 ||
                   field->datatype == pcl::PCLPointField::FLOAT64);
}

// Byte offset of point `index` in row-major order, honouring row padding.
std::size_t pointOffset(const pcl::PCLPointCloud2 &cloud, std::size_t index) {
  const std::size_t row = index / cloud.width;
  const std::size_t column = index % cloud.width;
  return row * cloud.row_step + column * cloud.point_step;
}

// Where a FLOAT32 or FLOAT64 field lies in a point.
struct FloatField {
  std::uint32_t offset = 0;
  bool is_double = false;
};

double readValue(const pcl::PCLPointCloud2 &cloud, std::size_t point_base, FloatField field) {
  const std::uint8_t *at = &cloud.data[point_base + field.offset];
  if (field.is_double) {
    double value;
    std::memcpy(&value, at, sizeof value);
    return value;
  }
  float value;
  std::memcpy(&value, at, sizeof value);
  return value;
}

// Three float fields the cloud is known to have.
std::array<FloatField, 3> floatFields(const pcl::PCLPointCloud2 &cloud,
                                      const std::array<const char *, 3> &names) {
  std::array<FloatField, 3> fields;
  for (int k = 0; k < 3; ++k) {
    const pcl::PCLPointField *field = findField(cloud.fields, names[k]);
    fields[k] = {field->offset, field->datatype == pcl::PCLPointField::FLOAT64};
  }
  return fields;
}

// Reads positions from a cloud whose layout checkCloudLayout accepted.
class PositionReader {
public:
  explicit PositionReader(const pcl::PCLPointCloud2 &cloud)
      : cloud_(cloud), fields_(floatFields(cloud, {"x", "y", "z"})),
        point_count_(static_cast<std::size_t>(cloud.width) * cloud.height) {}

  // False when `index` lies outside the cloud or the point is not finite.
  bool read(pcl::index_t index, std::array<float, 3> &position) const {
    if (index < 0 || static_cast<std::size_t>(index) >= point_count_)
      return false;
    const std::size_t base = pointOffset(cloud_, static_cast<std::size_t>(index));
    for (int axis = 0; axis < 3; ++axis) {
      position[axis] = static_cast<float>(readValue(cloud_, base, fields_[axis]));
      if (!std::isfinite(position[axis]))
        return false;
    }
    return true;
  }

private:
  const pcl::PCLPointCloud2 &cloud_;
  std::array<FloatField, 3> fields_;
  std::size_t point_count_;
};

// Marker geometry of a cloud whose layout can be read; none otherwise.
template <typename AddGeometry>
MarkerGeometry buildGeometry(const pcl::PCLPointCloud2 &cloud, AddGeometry add_geometry) {
  MarkerGeometry geometry;
  if (checkCloudLayout(cloud).empty())
    add_geometry(PositionReader(cloud), geometry);
  return geometry;
}

// PCL and ROS pack colour as 0xAARRGGBB in a 4-byte rgb or rgba field. Alpha
// is ignored: "rgb" fields often leave it 0, and RViz would hide the mesh.
const pcl::PCLPointField *colorField(const pcl::PCLPointCloud2 &cloud) {
  for (const char *name : {"rgb", "rgba"}) {
    const pcl::PCLPointField *field = findField(cloud.fields, name);
    if (field && datatypeSize(field->datatype) == 4)
      return field;
  }
  return nullptr;
}

std::array<float, 4> readColor(const pcl::PCLPointCloud2 &cloud, std::uint32_t field_offset,
                               std::size_t index) {
  std::uint32_t packed;
  std::memcpy(&packed, &cloud.data[pointOffset(cloud, index) + field_offset], sizeof packed);
  return {static_cast<float>((packed >> 16) & 0xff) / 255.0f,
          static_cast<float>((packed >> 8) & 0xff) / 255.0f,
          static_cast<float>(packed & 0xff) / 255.0f, 1.0f};
}

// The typed cloud of a cloud whose layout checkCloudLayout accepted (and, for
// PointNormal, with float normals): only what meshing reads. Unlike
// pcl::fromPCLPointCloud2 it does not warn, on every message, about the
// fields the point type has and the message lacks (a PointNormal's
// curvature), and it reads FLOAT64 fields. False, with the reason, when
// rounding double coordinates to float would harm the cloud.
template <typename PointT>
bool copyPoints(const pcl::PCLPointCloud2 &cloud, pcl::PointCloud<PointT> &points,
                std::string &error) {
  points.header = cloud.header;
  points.width = cloud.width;
  points.height = cloud.height;
  points.is_dense = cloud.is_dense;
  points.resize(static_cast<std::size_t>(cloud.width) * cloud.height);
  const std::array<FloatField, 3> xyz = floatFields(cloud, {"x", "y", "z"});
  std::array<FloatField, 3> normal{};
  if constexpr (pcl::traits::has_normal_v<PointT>)
    normal = floatFields(cloud, {"normal_x", "normal_y", "normal_z"});
  io_detail::CoordinateRounding rounding;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::size_t base = pointOffset(cloud, i);
    PointT &point = points[i];
    for (int k = 0; k < 3; ++k)
      point.data[k] = rounding.round(readValue(cloud, base, xyz[k]), k);
    if constexpr (pcl::traits::has_normal_v<PointT>)
      for (int k = 0; k < 3; ++k)
        point.data_n[k] = static_cast<float>(readValue(cloud, base, normal[k]));
  }
  return rounding.harmless(
      points.size(), [&](std::size_t i) { return Eigen::Vector3f(points[i].getVector3fMap()); },
      error);
}

template <typename PointT>
void meshTypedCloud(const pcl::PCLPointCloud2 &cloud, const pcl_ms::Parameters &parameters,
                    bool use_normals, MeshingOutcome &outcome) {
  const Clock::time_point conversion_start = Clock::now();
  typename pcl::PointCloud<PointT>::Ptr points(new pcl::PointCloud<PointT>);
  const bool usable = copyPoints(cloud, *points, outcome.error);
  outcome.conversion_seconds = secondsSince(conversion_start);
  if (!usable)
    return;

  pcl::MedialScaffoldReconstruction<PointT> reconstruction;
  reconstruction.setParameters(parameters);
  reconstruction.setUseNormals(use_normals);
  reconstruction.setInputCloud(points);

  // This overload copies the input into `output_points` (the polygon-mesh one
  // would pack it into a PCLPointCloud2, which costs more); the nodes publish
  // the message's own cloud instead.
  pcl::PointCloud<PointT> output_points;
  const Clock::time_point library_start = Clock::now();
  reconstruction.reconstruct(output_points, outcome.polygons);
  outcome.library_seconds = secondsSince(library_start);

  const pcl_ms::Result &result = reconstruction.getResult();
  outcome.finite_points = result.input_points - result.invalid_points;
  outcome.error = reconstruction.getErrorMessage();
  if (!outcome.error.empty()) {
    outcome.polygons.clear();
    return;
  }
  outcome.boundary_loops = reconstruction.getBoundaryLoops();
  outcome.median_circumradius = result.d_med;
}

} // namespace

bool hasNormalFields(const std::vector<pcl::PCLPointField> &fields) {
  return isFloatField(findField(fields, "normal_x")) &&
         isFloatField(findField(fields, "normal_y")) && isFloatField(findField(fields, "normal_z"));
}

MeshingPointType choosePointType(const std::vector<pcl::PCLPointField> &fields, bool use_normals) {
  return use_normals && hasNormalFields(fields) ? MeshingPointType::xyz_normal
                                                : MeshingPointType::xyz;
}

std::string checkCloudLayout(const pcl::PCLPointCloud2 &cloud) {
  std::ostringstream reason;
  const std::uint64_t points = static_cast<std::uint64_t>(cloud.width) * cloud.height;
  if (points == 0) {
    reason << "the cloud is empty (width " << cloud.width << ", height " << cloud.height << ")";
    return reason.str();
  }
  if (cloud.is_bigendian) {
    reason << "big-endian clouds are not supported";
    return reason.str();
  }
  for (const char *name : {"x", "y", "z"}) {
    const pcl::PCLPointField *field = findField(cloud.fields, name);
    if (!field) {
      reason << "the cloud has no '" << name << "' field";
      return reason.str();
    }
    if (!isFloatField(field)) {
      reason << "field '" << name << "' is not FLOAT32 or FLOAT64 (datatype "
             << static_cast<int>(field->datatype) << ")";
      return reason.str();
    }
  }
  // Every field this layer reads must lie inside the point.
  for (const pcl::PCLPointField &field : cloud.fields) {
    const std::uint64_t end =
        static_cast<std::uint64_t>(field.offset) +
        datatypeSize(field.datatype) * std::max<std::uint32_t>(field.count, 1);
    if (end > cloud.point_step) {
      reason << "field '" << field.name << "' ends at byte " << end << ", past point_step "
             << cloud.point_step;
      return reason.str();
    }
  }
  if (static_cast<std::uint64_t>(cloud.width) * cloud.point_step > cloud.row_step) {
    reason << "row_step " << cloud.row_step << " is shorter than width " << cloud.width
           << " x point_step " << cloud.point_step;
    return reason.str();
  }
  const std::uint64_t expected_bytes = static_cast<std::uint64_t>(cloud.row_step) * cloud.height;
  if (cloud.data.size() < expected_bytes) {
    reason << "the data has " << cloud.data.size() << " bytes, but row_step x height is "
           << expected_bytes;
    return reason.str();
  }
  return {};
}

MeshingOutcome meshCloud(const pcl::PCLPointCloud2 &cloud, const pcl_ms::Parameters &parameters) {
  MeshingOutcome outcome;
  outcome.error = checkCloudLayout(cloud);
  if (!outcome.error.empty())
    return outcome;
  if (parameters.use_normals && !hasNormalFields(cloud.fields))
    outcome.warning = "use_normals is set but the cloud has no float normal_x/y/z fields: "
                      "meshed without normals";
  try {
    if (choosePointType(cloud.fields, parameters.use_normals) == MeshingPointType::xyz_normal)
      meshTypedCloud<pcl::PointNormal>(cloud, parameters, true, outcome);
    else
      meshTypedCloud<pcl::PointXYZ>(cloud, parameters, false, outcome);
  } catch (const std::exception &error) {
    // Out of memory on a huge cloud, or anything PCL throws: report, don't die.
    outcome.polygons.clear();
    outcome.boundary_loops.clear();
    outcome.error = std::string("meshing failed: ") + error.what();
  }
  return outcome;
}

MarkerGeometry triangleListGeometry(const pcl::PCLPointCloud2 &cloud,
                                    const std::vector<pcl::Vertices> &polygons) {
  return buildGeometry(cloud, [&](const PositionReader &positions, MarkerGeometry &geometry) {
    const pcl::PCLPointField *color = colorField(cloud);
    geometry.points.reserve(3 * polygons.size());
    if (color)
      geometry.colors.reserve(3 * polygons.size());
    for (const pcl::Vertices &polygon : polygons) {
      if (polygon.vertices.size() != 3)
        continue;
      std::array<std::array<float, 3>, 3> corners;
      bool usable = true;
      for (int corner = 0; corner < 3 && usable; ++corner)
        usable = positions.read(polygon.vertices[corner], corners[corner]);
      if (!usable)
        continue;
      for (int corner = 0; corner < 3; ++corner) {
        geometry.points.push_back(corners[corner]);
        if (color)
          geometry.colors.push_back(
              readColor(cloud, color->offset, static_cast<std::size_t>(polygon.vertices[corner])));
      }
    }
  });
}

MarkerGeometry boundaryLineGeometry(const pcl::PCLPointCloud2 &cloud,
                                    const std::vector<pcl::Vertices> &loops) {
  return buildGeometry(cloud, [&](const PositionReader &positions, MarkerGeometry &geometry) {
    for (const pcl::Vertices &loop : loops) {
      const std::size_t length = loop.vertices.size();
      if (length < 2)
        continue;
      for (std::size_t i = 0; i < length; ++i) {
        std::array<float, 3> from_position, to_position;
        if (!positions.read(loop.vertices[i], from_position) ||
            !positions.read(loop.vertices[(i + 1) % length], to_position))
          continue;
        geometry.points.push_back(from_position);
        geometry.points.push_back(to_position);
      }
    }
  });
}

} // namespace ros_bridge
} // namespace pcl_ms
