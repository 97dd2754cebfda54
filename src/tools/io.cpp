// SPDX-License-Identifier: GPL-3.0-or-later
// File input and output. PCL's readers are used for .pcd and .ply clouds so
// that field conventions (rgb packing, normal names) match the rest of PCL,
// but only after the header and the body size have been checked here: PCL
// 1.13 crashes on some malformed PCD headers and would allocate whatever
// size a corrupt header claims. Meshes are read by small parsers of our own
// (mesh_readers.cpp) so that every format reports the same kind of errors;
// the parsing pieces they share with the cloud readers are in io_parsing.cpp.
#include <pcl_ms/io.h>

#include <pcl/PCLPointField.h>
#include <pcl/io/obj_io.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/io/vtk_io.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string_view>
#include <system_error>

#include "float_coordinates.h"
#include "io_parsing.h"
#include "mesh_readers.h"

#include <pcl_ms/mesh_file.h>

namespace pcl_ms {
namespace {

using namespace io_detail;
namespace fs = std::filesystem;

// ---------------------------------------------------------------------------
// Field checks shared by all cloud readers

const pcl::PCLPointField *findField(const pcl::PCLPointCloud2 &cloud, const std::string &name) {
  for (const pcl::PCLPointField &field : cloud.fields)
    if (field.name == name)
      return &field;
  return nullptr;
}

/// Whether a finite value is too large for the float the clouds store.
bool outOfFloatRange(double value) {
  return std::isfinite(value) && std::abs(value) > std::numeric_limits<float>::max();
}

bool isSingleFloatField(const pcl::PCLPointField *field) {
  return field && field->datatype == pcl::PCLPointField::FLOAT32 && field->count <= 1;
}

const char *datatypeName(std::uint8_t datatype) {
  switch (datatype) {
  case pcl::PCLPointField::INT8:
    return "int8";
  case pcl::PCLPointField::UINT8:
    return "uint8";
  case pcl::PCLPointField::INT16:
    return "int16";
  case pcl::PCLPointField::UINT16:
    return "uint16";
  case pcl::PCLPointField::INT32:
    return "int32";
  case pcl::PCLPointField::UINT32:
    return "uint32";
  case pcl::PCLPointField::FLOAT32:
    return "float32";
  case pcl::PCLPointField::FLOAT64:
    return "float64";
  default:
    return "unknown type";
  }
}

/// PCL's point types hold float coordinates and normals, so float64 fields
/// of those names (CGAL and Open3D write PLY so) are narrowed in place: each
/// value goes to the first four of its eight bytes, and the record layout
/// stays as it is. False, with the reason, when a value is out of float
/// range or the rounding would harm the cloud (CoordinateRounding).
bool narrowDoubleFields(pcl::PCLPointCloud2 &cloud, std::string &error) {
  const std::size_t points = static_cast<std::size_t>(cloud.width) * cloud.height;
  if (cloud.data.size() != points * cloud.point_step)
    return true; // checkCloudLayout reports it
  const auto doubleField = [&](const char *name) -> pcl::PCLPointField * {
    for (pcl::PCLPointField &field : cloud.fields)
      if (field.name == name)
        return field.datatype == pcl::PCLPointField::FLOAT64 && field.count <= 1 &&
                       field.offset + sizeof(double) <= cloud.point_step
                   ? &field
                   : nullptr;
    return nullptr;
  };
  const auto narrow = [&](pcl::PCLPointField &field, const auto &round) {
    for (std::size_t p = 0; p < points; ++p) {
      std::uint8_t *at = &cloud.data[p * cloud.point_step + field.offset];
      double value;
      std::memcpy(&value, at, sizeof value);
      if (outOfFloatRange(value)) {
        std::ostringstream message;
        message << "point " << p << ": " << field.name << " = " << value
                << " is out of float range";
        error = message.str();
        return false;
      }
      const float narrowed = round(value);
      std::memcpy(at, &narrowed, sizeof narrowed);
    }
    field.datatype = pcl::PCLPointField::FLOAT32;
    field.count = 1;
    return true;
  };
  CoordinateRounding rounding;
  bool rounded = false;
  static const char *const axes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k)
    if (pcl::PCLPointField *field = doubleField(axes[k])) {
      if (!narrow(*field, [&](double value) { return rounding.round(value, k); }))
        return false;
      rounded = true;
    }
  for (const char *name : {"normal_x", "normal_y", "normal_z"})
    if (pcl::PCLPointField *field = doubleField(name))
      if (!narrow(*field, [](double value) { return static_cast<float>(value); }))
        return false;
  const pcl::PCLPointField *x = findField(cloud, "x"), *y = findField(cloud, "y"),
                           *z = findField(cloud, "z");
  if (!rounded || !isSingleFloatField(x) || !isSingleFloatField(y) || !isSingleFloatField(z))
    return true; // nothing rounded, or checkCloudLayout refuses the fields
  const auto stored = [&](std::size_t p) {
    Eigen::Vector3f position;
    const std::uint8_t *record = &cloud.data[p * cloud.point_step];
    std::memcpy(&position[0], record + x->offset, sizeof(float));
    std::memcpy(&position[1], record + y->offset, sizeof(float));
    std::memcpy(&position[2], record + z->offset, sizeof(float));
    return position;
  };
  return rounding.harmless(points, stored, error);
}

bool checkCloudLayout(const pcl::PCLPointCloud2 &cloud, std::string &error) {
  for (const char *name : {"x", "y", "z"}) {
    const pcl::PCLPointField *field = findField(cloud, name);
    if (!field) {
      error = std::string("the cloud has no '") + name + "' field";
      return false;
    }
    if (!isSingleFloatField(field)) {
      error = std::string("field '") + name + "' is " + datatypeName(field->datatype) + " (count " +
              std::to_string(field->count) + "); float32 or float64 coordinates are required";
      return false;
    }
    if (field->offset + sizeof(float) > cloud.point_step) {
      error = std::string("field '") + name + "' lies outside the point record";
      return false;
    }
  }
  const std::size_t points = static_cast<std::size_t>(cloud.width) * cloud.height;
  if (points == 0) {
    error = "the file contains no points";
    return false;
  }
  if (cloud.data.size() != points * cloud.point_step) {
    error = "inconsistent cloud: " + std::to_string(points) + " points of " +
            std::to_string(cloud.point_step) + " bytes but " + std::to_string(cloud.data.size()) +
            " bytes of data";
    return false;
  }
  return true;
}

// ---------------------------------------------------------------------------
// PCD: header check before PCL's reader sees the file

bool checkPcdAsciiBody(std::istream &in, std::size_t line_number, std::uint64_t points,
                       std::uint64_t values_per_point, std::string &error) {
  std::string line;
  std::uint64_t lines_read = 0;
  while (lines_read < points && std::getline(in, line)) {
    ++line_number;
    const std::size_t values = splitWords(line).size();
    if (values == 0)
      continue;
    if (values != values_per_point) {
      error = "line " + std::to_string(line_number) + ": expected " +
              std::to_string(values_per_point) + " values, found " + std::to_string(values) +
              (in.eof() ? " (file truncated?)" : "");
      return false;
    }
    ++lines_read;
  }
  if (lines_read < points) {
    error = "truncated PCD file: " + std::to_string(lines_read) + " of " + std::to_string(points) +
            " points";
    return false;
  }
  return true;
}

bool checkPcdHeader(const std::string &path, std::uintmax_t file_size, std::string &error) {
  std::ifstream in(path, std::ios::binary);
  PcdHeader header;
  if (!parsePcdHeader(in, header, error))
    return false;
  const std::uint64_t points = header.points;

  // Compare what the header promises with what the file holds, in doubles
  // so that absurd counts cannot overflow.
  const double body = static_cast<double>(file_size) - static_cast<double>(header.header_bytes);
  const double expected = static_cast<double>(points) * static_cast<double>(header.point_bytes);
  if (header.data == PcdData::Ascii) {
    // Each value needs at least one character and one separator.
    if (static_cast<double>(points) * static_cast<double>(header.values_per_point) * 2 - 1 > body) {
      error = "truncated PCD file: the header declares " + std::to_string(points) +
              " points but the data is too short";
      return false;
    }
    // PCL silently accepts a short last line, so count the values per line.
    return checkPcdAsciiBody(in, header.header_lines, points, header.values_per_point, error);
  } else if (header.data == PcdData::Binary) {
    if (expected > body) {
      error = "truncated PCD file: " + std::to_string(points) + " points need " +
              std::to_string(static_cast<std::uint64_t>(expected)) + " bytes, the file has " +
              std::to_string(static_cast<std::uint64_t>(std::max(body, 0.0)));
      return false;
    }
  } else {
    std::uint32_t compressed = 0, uncompressed = 0;
    if (body < 8 || !in.read(reinterpret_cast<char *>(&compressed), 4) ||
        !in.read(reinterpret_cast<char *>(&uncompressed), 4)) {
      error = "truncated PCD file: compressed block sizes are missing";
      return false;
    }
    if (static_cast<double>(uncompressed) != expected) {
      error = "corrupt PCD file: the compressed block does not match the header";
      return false;
    }
    if (static_cast<double>(compressed) + 8 > body) {
      error = "truncated PCD file: the compressed block is cut short";
      return false;
    }
  }
  return true;
}

// ---------------------------------------------------------------------------
// Point clouds

bool loadPcdCloud(const std::string &path, std::uintmax_t size, pcl::PCLPointCloud2 &cloud,
                  Eigen::Vector4f &sensor_origin, std::string &error) {
  if (!checkPcdHeader(path, size, error))
    return false;
  Eigen::Quaternionf sensor_orientation;
  if (pcl::io::loadPCDFile(path, cloud, sensor_origin, sensor_orientation) < 0) {
    error = "PCL's PCD reader rejected the data (corrupt or truncated file)";
    return false;
  }
  return true;
}

/// PCL turns range scans (element range_grid) into an organized grid with NaN
/// in empty cells, and takes width and height from obj_info lines even when
/// they do not match the vertex count. Callers want the scanned vertices.
void unorganizeScan(const PlyHeader &header, pcl::PCLPointCloud2 &cloud) {
  const PlyElement *vertex = header.find("vertex");
  const std::size_t points = static_cast<std::size_t>(cloud.width) * cloud.height;
  if (!vertex || points == vertex->count)
    return;
  const pcl::PCLPointField *x = findField(cloud, "x");
  if (header.find("range_grid") && isSingleFloatField(x) &&
      cloud.data.size() == points * cloud.point_step) {
    std::size_t kept = 0;
    for (std::size_t p = 0; p < points; ++p) {
      const std::uint8_t *record = &cloud.data[p * cloud.point_step];
      float value;
      std::memcpy(&value, record + x->offset, sizeof(float));
      if (std::isnan(value))
        continue; // an empty grid cell
      std::memmove(&cloud.data[kept * cloud.point_step], record, cloud.point_step);
      ++kept;
    }
    cloud.data.resize(kept * cloud.point_step);
    cloud.width = static_cast<std::uint32_t>(kept);
  } else if (cloud.data.size() == vertex->count * cloud.point_step) {
    cloud.width = static_cast<std::uint32_t>(vertex->count);
  } else {
    return; // leave it to checkCloudLayout to report
  }
  cloud.height = 1;
  cloud.row_step = cloud.width * cloud.point_step;
  cloud.is_dense = false;
}

bool loadPlyCloud(const std::string &path, std::uintmax_t size, pcl::PCLPointCloud2 &cloud,
                  std::string &error) {
  PlyHeader header;
  {
    std::ifstream in(path, std::ios::binary);
    if (!parsePlyHeader(in, header, error) || !checkPlyBodySize(header, size, error))
      return false;
  }
  if (!header.find("vertex")) {
    error = "the PLY file has no vertex element";
    return false;
  }
  // Reading into a mesh gives faces somewhere to go, so mesh files load
  // without PCL complaining about unhandled properties.
  pcl::PolygonMesh mesh;
  if (pcl::io::loadPLYFile(path, mesh) < 0) {
    error = "PCL's PLY reader rejected the file (corrupt or truncated)";
    return false;
  }
  cloud = std::move(mesh.cloud);
  unorganizeScan(header, cloud);
  return true;
}

/// A cloud of FLOAT32 columns (x y z [normal_x normal_y normal_z]) from
/// `values`, `columns` per point.
void makeFloatCloud(const std::vector<float> &values, std::size_t columns,
                    pcl::PCLPointCloud2 &cloud) {
  const char *names[] = {"x", "y", "z", "normal_x", "normal_y", "normal_z"};
  cloud = pcl::PCLPointCloud2();
  for (std::size_t c = 0; c < columns; ++c) {
    pcl::PCLPointField field;
    field.name = names[c];
    field.offset = static_cast<std::uint32_t>(c * sizeof(float));
    field.datatype = pcl::PCLPointField::FLOAT32;
    field.count = 1;
    cloud.fields.push_back(field);
  }
  cloud.point_step = static_cast<std::uint32_t>(columns * sizeof(float));
  cloud.width = static_cast<std::uint32_t>(values.size() / columns);
  cloud.height = 1;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense =
      std::all_of(values.begin(), values.end(), [](float v) { return std::isfinite(v); });
  cloud.data.resize(values.size() * sizeof(float));
  std::memcpy(cloud.data.data(), values.data(), cloud.data.size());
}

bool loadXyzCloud(const std::string &path, pcl::PCLPointCloud2 &cloud, std::string &error) {
  std::string bytes;
  if (!readFileBytes(path, bytes, error))
    return false;

  std::vector<float> values;
  std::size_t columns = 0;
  CoordinateRounding rounding;
  WordLines lines(bytes);
  while (lines.next()) {
    const std::vector<std::string_view> &words = lines.words();
    const std::string where = "line " + std::to_string(lines.lineNumber()) + ": ";
    if (columns == 0) {
      if (words.size() != 3 && words.size() != 6) {
        error = where + "expected 3 (x y z) or 6 (x y z nx ny nz) columns, found " +
                std::to_string(words.size());
        return false;
      }
      columns = words.size();
    } else if (words.size() != columns) {
      const bool truncated = !lines.endsWithNewline() && words.size() < columns;
      error = where + "expected " + std::to_string(columns) + " columns, found " +
              std::to_string(words.size()) + (truncated ? " (file truncated?)" : "");
      return false;
    }
    for (std::string_view word : words) {
      double value = 0;
      if (!parseDouble(word, value)) {
        error = where + printable(word) + " is not a number";
        return false;
      }
      if (outOfFloatRange(value)) {
        error = where + printable(word) + " is out of float range";
        return false;
      }
      const std::size_t column = values.size() % columns;
      values.push_back(column < 3 ? rounding.round(value, static_cast<int>(column))
                                  : static_cast<float>(value));
    }
  }
  if (values.empty()) {
    error = "the file contains no points";
    return false;
  }
  if (!rounding.harmless(
          values.size() / columns,
          [&](std::size_t i) { return Eigen::Vector3f(&values[i * columns]); }, error))
    return false;
  makeFloatCloud(values, columns, cloud);
  return true;
}

// ---------------------------------------------------------------------------
// Saving

/// PCL's mesh writers declare properties by field name but write values only
/// for the types they expect, so a known name with an unexpected type (say a
/// float64 normal_x) yields a corrupt file. Keep only fields they handle.
bool writerHandlesField(const pcl::PCLPointField &field) {
  if (field.count > 1)
    return false;
  static const char *float_fields[] = {"x",        "y",        "z",        "rgb",
                                       "normal_x", "normal_y", "normal_z", "curvature"};
  for (const char *name : float_fields)
    if (field.name == name)
      return field.datatype == pcl::PCLPointField::FLOAT32;
  return field.name == "rgba" && field.datatype == pcl::PCLPointField::UINT32;
}

bool checkMeshForSaving(const pcl::PolygonMesh &mesh, std::string &error) {
  if (!checkCloudLayout(mesh.cloud, error)) {
    if (error == "the file contains no points")
      error = "the mesh has no vertices";
    return false;
  }
  const std::size_t points = static_cast<std::size_t>(mesh.cloud.width) * mesh.cloud.height;
  for (std::size_t p = 0; p < mesh.polygons.size(); ++p) {
    const pcl::Indices &corners = mesh.polygons[p].vertices;
    if (corners.empty()) {
      error = "polygon " + std::to_string(p) + " has no vertices";
      return false;
    }
    for (const pcl::index_t corner : corners)
      if (corner < 0 || static_cast<std::size_t>(corner) >= points) {
        error = "polygon " + std::to_string(p) + " references vertex " + std::to_string(corner) +
                " but the cloud has " + std::to_string(points) + " points";
        return false;
      }
  }
  return true;
}

} // namespace

// ---------------------------------------------------------------------------
// Public functions

bool hasNormals(const pcl::PCLPointCloud2 &cloud) {
  return isSingleFloatField(findField(cloud, "normal_x")) &&
         isSingleFloatField(findField(cloud, "normal_y")) &&
         isSingleFloatField(findField(cloud, "normal_z"));
}

namespace {

/// The vertices of an .obj, .off, .vtk or .stl mesh as a cloud, in file
/// order (an STL's welded vertices in order of first use); faces may be
/// absent (a vertex-only OFF is a point cloud).
bool loadMeshVerticesCloud(const std::string &path, pcl::PCLPointCloud2 &cloud,
                           std::string &reason) {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Triangle> triangles;
  if (!readMeshFile(path, vertices, triangles, reason))
    return false;
  if (vertices.empty()) {
    reason = "the file contains no vertices";
    return false;
  }
  std::vector<float> values;
  values.reserve(3 * vertices.size());
  CoordinateRounding rounding;
  for (std::size_t i = 0; i < vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double value = vertices[i][k];
      if (outOfFloatRange(value)) {
        reason = "vertex " + std::to_string(i) + " is out of float range";
        return false;
      }
      values.push_back(rounding.round(value, k));
    }
  if (!rounding.harmless(
          vertices.size(), [&](std::size_t i) { return Eigen::Vector3f(&values[3 * i]); }, reason))
    return false;
  makeFloatCloud(values, 3, cloud);
  return true;
}

} // namespace

bool loadPointCloud(const std::string &path, pcl::PCLPointCloud2 &cloud, std::string &error,
                    Eigen::Vector4f *sensor_origin) {
  cloud = pcl::PCLPointCloud2();
  Eigen::Vector4f origin = Eigen::Vector4f::Zero();
  std::string reason;
  bool ok = false;
  try {
    const std::string extension = fileExtension(path);
    std::uintmax_t size = 0;
    if (!checkInputFile(path, size, reason))
      ok = false;
    else if (extension == ".pcd")
      ok = loadPcdCloud(path, size, cloud, origin, reason);
    else if (extension == ".ply")
      ok = loadPlyCloud(path, size, cloud, reason);
    else if (extension == ".xyz" || extension == ".txt")
      ok = loadXyzCloud(path, cloud, reason);
    else if (extension == ".obj" || extension == ".off" || extension == ".vtk" ||
             extension == ".stl")
      ok = loadMeshVerticesCloud(path, cloud, reason);
    else
      reason =
          unknownFormat(extension, "point cloud",
                        ".pcd, .ply, .xyz, .txt, or a mesh's vertices: .obj, .off, .vtk, .stl");
    ok = ok && narrowDoubleFields(cloud, reason) && checkCloudLayout(cloud, reason);
  } catch (const std::exception &exception) {
    reason = std::string("unexpected failure: ") + exception.what();
    ok = false;
  }
  if (!ok) {
    cloud = pcl::PCLPointCloud2();
    origin = Eigen::Vector4f::Zero();
    error = path + ": " + reason;
  }
  if (sensor_origin)
    *sensor_origin = origin;
  return ok;
}

bool isMeshOutputSupported(const std::string &path) {
  const std::string extension = fileExtension(path);
  return extension == ".ply" || extension == ".vtk" || extension == ".obj";
}

bool saveMesh(const std::string &path, const pcl::PolygonMesh &mesh, std::string &error,
              bool binary) {
  std::string reason;
  bool created = false, ok = false;
  try {
    const std::string extension = fileExtension(path);
    if (!isMeshOutputSupported(path)) {
      reason = unknownFormat(extension, "mesh", ".ply, .vtk or .obj");
    } else if (checkMeshForSaving(mesh, reason)) {
      // PCL's writers do not all check that the file opened; find out first.
      std::error_code code;
      if (fs::is_directory(path, code)) {
        reason = "is a directory";
      } else if (!std::ofstream(path, std::ios::binary | std::ios::trunc)) {
        reason = std::string("cannot open for writing: ") + std::strerror(errno);
      } else {
        created = true;
        const pcl::PolygonMesh *to_write = &mesh;
        pcl::PolygonMesh filtered;
        const auto handled =
            std::count_if(mesh.cloud.fields.begin(), mesh.cloud.fields.end(), writerHandlesField);
        if (static_cast<std::size_t>(handled) != mesh.cloud.fields.size()) {
          filtered = mesh;
          auto &fields = filtered.cloud.fields;
          fields.erase(std::remove_if(fields.begin(), fields.end(),
                                      [](const pcl::PCLPointField &field) {
                                        return !writerHandlesField(field);
                                      }),
                       fields.end());
          to_write = &filtered;
        }
        // Enough digits that float coordinates survive the text formats.
        const unsigned precision = std::numeric_limits<float>::max_digits10;
        int status = 0;
        if (extension == ".ply")
          status = binary ? pcl::io::savePLYFileBinary(path, *to_write)
                          : pcl::io::savePLYFile(path, *to_write, precision);
        else if (extension == ".vtk")
          status = pcl::io::saveVTKFile(path, *to_write, precision);
        else
          status = pcl::io::saveOBJFile(path, *to_write, precision);
        if (status < 0)
          reason = "PCL's writer failed";
        else if (fs::file_size(path, code) == 0 || code)
          reason = "nothing was written";
        else
          ok = true;
      }
    }
  } catch (const std::exception &exception) {
    reason = std::string("unexpected failure: ") + exception.what();
    ok = false;
  }
  if (!ok) {
    if (created) {
      std::error_code ignored;
      fs::remove(path, ignored);
    }
    error = path + ": " + reason;
  }
  return ok;
}

bool saveMedialAxis(const std::string &path, const MedialAxis &axis, std::string &error,
                    bool binary) {
  const std::size_t nodes = axis.node_positions.size();
  std::string reason;
  if (fileExtension(path) != ".ply")
    reason = unknownFormat(fileExtension(path), "medial axis", ".ply");
  else if (axis.node_radii.size() != nodes || axis.node_side.size() != nodes)
    reason = "the medial axis has " + std::to_string(nodes) + " nodes but " +
             std::to_string(axis.node_radii.size()) + " radii and " +
             std::to_string(axis.node_side.size()) + " sides";
  else if (nodes > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    reason = "too many nodes for PLY's int indices";
  for (std::size_t c = 0; reason.empty() && c < axis.curves.size(); ++c)
    if (axis.curves[c][0] >= nodes || axis.curves[c][1] >= nodes)
      reason = "curve " + std::to_string(c) + " joins a node that does not exist";
  std::error_code code;
  if (reason.empty() && fs::is_directory(path, code))
    reason = "is a directory";
  if (!reason.empty()) {
    error = path + ": " + reason;
    return false;
  }

  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    error = path + ": cannot open for writing: " + std::strerror(errno);
    return false;
  }
  out << "ply\nformat "
      << (!binary                ? "ascii"
          : hostIsLittleEndian() ? "binary_little_endian"
                                 : "binary_big_endian")
      << " 1.0\n"
      << "comment pcl_ms medial axis: A1^4 nodes (Voronoi vertices that are poles) with the\n"
      << "comment radius of their maximal ball; inside 1 = inside a closed component,\n"
      << "comment 0 = outside, 2 = next to an open part; edges are A1^3 shock curves\n"
      << "element vertex " << nodes << "\n"
      << "property float x\nproperty float y\nproperty float z\nproperty float radius\n"
      << "property uchar inside\n"
      << "element edge " << axis.curves.size() << "\n"
      << "property int vertex1\nproperty int vertex2\nend_header\n";
  if (binary) {
    for (std::size_t n = 0; n < nodes; ++n) {
      const float values[4] = {static_cast<float>(axis.node_positions[n].x()),
                               static_cast<float>(axis.node_positions[n].y()),
                               static_cast<float>(axis.node_positions[n].z()),
                               static_cast<float>(axis.node_radii[n])};
      out.write(reinterpret_cast<const char *>(values), sizeof(values));
      out.put(static_cast<char>(axis.node_side[n]));
    }
    for (const auto &curve : axis.curves) {
      const std::int32_t ends[2] = {static_cast<std::int32_t>(curve[0]),
                                    static_cast<std::int32_t>(curve[1])};
      out.write(reinterpret_cast<const char *>(ends), sizeof(ends));
    }
  } else {
    out.precision(std::numeric_limits<float>::max_digits10);
    for (std::size_t n = 0; n < nodes; ++n)
      out << static_cast<float>(axis.node_positions[n].x()) << ' '
          << static_cast<float>(axis.node_positions[n].y()) << ' '
          << static_cast<float>(axis.node_positions[n].z()) << ' '
          << static_cast<float>(axis.node_radii[n]) << ' ' << int(axis.node_side[n]) << '\n';
    for (const auto &curve : axis.curves)
      out << curve[0] << ' ' << curve[1] << '\n';
  }
  out.close();
  if (!out) {
    fs::remove(path, code);
    error = path + ": writing failed";
    return false;
  }
  return true;
}

} // namespace pcl_ms
