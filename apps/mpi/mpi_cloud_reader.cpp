// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpi_cloud_reader.h"

#include "io_parsing.h"

#include <pcl_ms/mesh_file.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace pcl_ms_mpi {

using pcl_ms::io_detail::PcdData;
using pcl_ms::io_detail::PcdField;
using pcl_ms::io_detail::PcdHeader;
using pcl_ms::io_detail::PlyElement;
using pcl_ms::io_detail::PlyFormat;
using pcl_ms::io_detail::PlyHeader;
using pcl_ms::io_detail::PlyProperty;
using pcl_ms::io_detail::PlyType;

namespace {

bool describeBinaryPcd(std::istream &in, std::uintmax_t size, BinaryCloudLayout &layout,
                       std::string &fields) {
  PcdHeader header;
  std::string ignored;
  if (!pcl_ms::io_detail::parsePcdHeader(in, header, ignored) || header.data != PcdData::Binary ||
      header.points >= UINT32_MAX)
    return false;
  BinaryCloudLayout found;
  static const char *const axes[3] = {"x", "y", "z"};
  static const char *const normals[3] = {"normal_x", "normal_y", "normal_z"};
  const auto isSingleFloat = [](const PcdField *field) {
    return field && field->type == 'F' && field->size == 4 && field->count == 1;
  };
  for (int k = 0; k < 3; ++k) {
    const PcdField *axis = header.find(axes[k]);
    if (!isSingleFloat(axis))
      return false;
    found.xyz[k] = static_cast<std::uint32_t>(axis->offset);
    // Normals of another type are left to rank 0's reader, which narrows
    // double ones to float.
    const PcdField *normal = header.find(normals[k]);
    if (normal && !isSingleFloat(normal))
      return false;
    if (normal)
      found.normal[k] = static_cast<std::int32_t>(normal->offset);
  }
  // More records than the file could hold: rank 0's guarded loader reports
  // it, and record offsets below cannot overflow. So does a coordinate
  // named twice.
  for (const char *axis : axes)
    if (std::count_if(header.fields.begin(), header.fields.end(),
                      [&](const PcdField &field) { return field.name == axis; }) != 1)
      return false;
  if (header.points > size / header.point_bytes)
    return false;
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(header.viewpoint[k]))
      return false;
  found.data_offset = header.header_bytes;
  found.points = header.points;
  found.record_bytes = header.point_bytes;
  found.file_size = size;
  found.width = static_cast<std::uint32_t>(header.width);
  found.height = static_cast<std::uint32_t>(header.height);
  found.xyz_only = header.fields.size() == 3 && header.point_bytes == 12 && found.xyz[0] == 0 &&
                   found.xyz[1] == 4 && found.xyz[2] == 8;
  for (int k = 0; k < 3; ++k)
    found.origin[k] = static_cast<float>(header.viewpoint[k]);
  layout = found;
  fields.clear();
  for (const PcdField &field : header.fields)
    fields += (fields.empty() ? "" : " ") + field.name;
  return true;
}

/// Where an element after the vertices starts in the file, and the size of
/// its records.
struct ElementSpan {
  std::uint64_t begin = 0;
  std::uint64_t record_bytes = 0;
};

/// The spans of the elements after the vertices (entry e - 1 for element e),
/// which end at `end`. False when one has a list property (records of
/// varying size, such as faces) or they cannot all fit in `size` bytes.
bool spansAfterVertices(const PlyHeader &header, std::uint64_t vertices_end, std::uintmax_t size,
                        std::vector<ElementSpan> &spans, std::uint64_t &end) {
  spans.clear();
  std::uint64_t bytes = 0;
  for (std::size_t e = 1; e < header.elements.size(); ++e) {
    ElementSpan span;
    for (const PlyProperty &property : header.elements[e].properties) {
      if (property.is_list)
        return false;
      span.record_bytes += pcl_ms::io_detail::plyTypeSize(property.value_type);
    }
    if (span.record_bytes > 0 && header.elements[e].count > size / span.record_bytes)
      return false;
    span.begin = vertices_end + bytes;
    bytes += span.record_bytes * header.elements[e].count;
    if (bytes > size)
      return false;
    spans.push_back(span);
  }
  end = vertices_end + bytes;
  return true;
}

/// The cloud's width and height as PCL's reader and pcl_ms::loadPointCloud
/// leave them: a camera element's int viewportx and viewporty (its last
/// record's) replace the vertex count and 1, and a cloud whose width times
/// height is not the vertex count is made one row again. False if the
/// camera's bytes cannot be read.
bool readViewport(std::istream &in, const PlyHeader &header, const std::vector<ElementSpan> &spans,
                  std::uint32_t &width, std::uint32_t &height) {
  const std::uint64_t points = header.elements.front().count;
  std::uint64_t viewport[2] = {points, 1};
  for (std::size_t e = 1; e < header.elements.size(); ++e) {
    const PlyElement &element = header.elements[e];
    if (element.name != "camera" || element.count == 0)
      continue;
    const ElementSpan &span = spans[e - 1];
    std::uint64_t property_offset = 0;
    for (const PlyProperty &property : element.properties) {
      const int axis = property.name == "viewportx" ? 0 : property.name == "viewporty" ? 1 : -1;
      if (axis >= 0 && property.value_type == PlyType::Int32) {
        std::int32_t value = 0;
        in.clear();
        if (!in.seekg(static_cast<std::streamoff>(
                span.begin + (element.count - 1) * span.record_bytes + property_offset)) ||
            !in.read(reinterpret_cast<char *>(&value), sizeof value))
          return false;
        viewport[axis] = static_cast<std::uint32_t>(value);
      }
      property_offset += pcl_ms::io_detail::plyTypeSize(property.value_type);
    }
  }
  const bool rows = viewport[0] * viewport[1] == points;
  width = static_cast<std::uint32_t>(rows ? viewport[0] : points);
  height = static_cast<std::uint32_t>(rows ? viewport[1] : 1);
  return true;
}

bool describeBinaryPly(std::istream &in, std::uintmax_t size, BinaryCloudLayout &layout,
                       std::string &fields) {
  PlyHeader header;
  std::string ignored;
  if (!pcl_ms::io_detail::parsePlyHeader(in, header, ignored) ||
      header.format != PlyFormat::BinaryLittleEndian || header.has_obj_info ||
      header.find("range_grid") || header.elements.empty() ||
      header.elements.front().name != "vertex")
    return false;
  // The vertices come first, so their records start right after the header.
  const PlyElement &vertices = header.elements.front();
  if (vertices.count == 0 || vertices.count >= UINT32_MAX || header.find("vertex") != &vertices)
    return false;
  BinaryCloudLayout found;
  static const char *const axes[3] = {"x", "y", "z"};
  static const char *const normals[3] = {"normal_x", "normal_y", "normal_z"};
  // PCL writes normals as nx, ny, nz to PLY and reads them back as normal_x...
  static const char *const short_normals[3] = {"nx", "ny", "nz"};
  std::array<int, 3> axis_count = {0, 0, 0}, normal_count = {0, 0, 0};
  std::uint64_t offset = 0;
  std::string names;
  for (const PlyProperty &property : vertices.properties) {
    if (property.is_list)
      return false; // records of varying size
    std::string name = property.name;
    for (int k = 0; k < 3; ++k) {
      if (name == short_normals[k])
        name = normals[k];
      if (name == axes[k]) {
        if (property.value_type != PlyType::Float32)
          return false;
        found.xyz[k] = static_cast<std::uint32_t>(offset);
        ++axis_count[k];
      } else if (name == normals[k]) {
        if (property.value_type != PlyType::Float32)
          return false; // as for a PCD
        found.normal[k] = static_cast<std::int32_t>(offset);
        ++normal_count[k];
      }
    }
    offset += pcl_ms::io_detail::plyTypeSize(property.value_type);
    names += (names.empty() ? "" : " ") + name;
  }
  // A coordinate or normal named twice is left to rank 0's reader.
  if (axis_count != std::array<int, 3>{1, 1, 1} ||
      *std::max_element(normal_count.begin(), normal_count.end()) > 1 || offset > UINT32_MAX)
    return false;
  // More records than the file could hold: rank 0's guarded loader reports it.
  if (vertices.count > size / offset)
    return false;
  // What follows the vertices must be of fixed size (PCL's camera element,
  // not faces), so that a file cut short after the vertices is noticed too:
  // then rank 0's reader reports it. A file cut within the vertices is
  // reported by the rank whose range is missing, as for a PCD (by rank 0's
  // reader if the cut-off camera holds a viewport to read).
  const std::uint64_t vertices_end = header.header_bytes + vertices.count * offset;
  std::vector<ElementSpan> spans;
  std::uint64_t elements_end = 0;
  if (!spansAfterVertices(header, vertices_end, size, spans, elements_end))
    return false;
  if (size >= vertices_end && size < elements_end)
    return false;
  found.data_offset = header.header_bytes;
  found.points = vertices.count;
  found.record_bytes = offset;
  found.file_size = size;
  if (!readViewport(in, header, spans, found.width, found.height))
    return false;
  found.xyz_only = vertices.properties.size() == 3 && offset == 12 && found.xyz[0] == 0 &&
                   found.xyz[1] == 4 && found.xyz[2] == 8;
  found.ply = 1;
  layout = found;
  fields = names;
  return true;
}

} // namespace

bool describeBinaryCloud(const std::string &path, BinaryCloudLayout &layout, std::string &fields) {
  fields.clear();
  // Binary PCD data is the writer's memory, little-endian in practice; only
  // little-endian PLY is read in parts.
  if (!pcl_ms::io_detail::hostIsLittleEndian())
    return false;
  std::error_code code;
  const std::uintmax_t size = std::filesystem::file_size(path, code);
  if (code)
    return false;
  std::ifstream in(path, std::ios::binary);
  const std::string extension = pcl_ms::fileExtension(path);
  if (extension == ".pcd")
    return describeBinaryPcd(in, size, layout, fields);
  if (extension == ".ply")
    return describeBinaryPly(in, size, layout, fields);
  return false;
}

bool readRecords(const std::string &path, const BinaryCloudLayout &layout, std::uint64_t begin,
                 std::uint64_t end, std::vector<unsigned char> &bytes, std::string &error) {
  bytes.clear();
  if (begin == end) // a rank with no part need not see the file
    return true;
  const std::uint64_t first = layout.data_offset + begin * layout.record_bytes;
  const std::uint64_t last = layout.data_offset + end * layout.record_bytes;
  std::error_code code;
  const std::uintmax_t size = std::filesystem::file_size(path, code);
  if (code) {
    error = path + ": " + code.message();
    return false;
  }
  if (last > size) {
    error = path +
            (layout.ply ? ": truncated PLY file: points " : ": truncated PCD file: points ") +
            std::to_string(begin) + " to " + std::to_string(end) + " need bytes " +
            std::to_string(first) + " to " + std::to_string(last) + ", the file ends at byte " +
            std::to_string(size);
    return false;
  }
  bytes.resize(last - first);
  std::ifstream in(path, std::ios::binary);
  if (!in || !in.seekg(static_cast<std::streamoff>(first)) ||
      !in.read(reinterpret_cast<char *>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()))) {
    error = path + ": cannot read points " + std::to_string(begin) + " to " + std::to_string(end) +
            ": " + std::strerror(errno);
    return false;
  }
  return true;
}

bool PlyFromInputWriter::open(const std::string &output, const std::string &input,
                              const BinaryCloudLayout &layout, std::uint64_t faces) {
  output_ = output;
  out_.open(output, std::ios::binary | std::ios::trunc);
  if (!out_) {
    reason_ = std::string("cannot open for writing: ") + std::strerror(errno);
    return false;
  }
  created_ = true;
  // The header pcl::io::savePLYFileBinary writes for such a mesh.
  out_ << "ply\nformat binary_little_endian 1.0\ncomment PCL generated\nelement vertex "
       << layout.points << "\nproperty float x\nproperty float y\nproperty float z\nelement face "
       << faces << "\nproperty list uchar int vertex_indices\nend_header\n";
  // The vertex block is the input's x y z records as they are.
  constexpr std::uint64_t block = std::uint64_t(1) << 20;
  std::vector<unsigned char> bytes;
  for (std::uint64_t begin = 0; begin < layout.points && reason_.empty(); begin += block) {
    const std::uint64_t end = std::min(layout.points, begin + block);
    if (!readRecords(input, layout, begin, end, bytes, reason_))
      break;
    out_.write(reinterpret_cast<const char *>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
  }
  return reason_.empty();
}

bool PlyFromInputWriter::add(const std::array<std::uint32_t, 3> *triangles, std::size_t count) {
  if (!created_ || !reason_.empty())
    return false;
  faces_.resize(count * 13);
  char *at = faces_.data();
  for (std::size_t t = 0; t < count; ++t) {
    *at++ = 3;
    std::memcpy(at, triangles[t].data(), 12);
    at += 12;
  }
  out_.write(faces_.data(), static_cast<std::streamsize>(faces_.size()));
  return true;
}

bool PlyFromInputWriter::close(std::string &error) {
  if (created_) {
    out_.flush();
    if (reason_.empty() && !out_)
      reason_ = std::string("write failed: ") + std::strerror(errno);
    out_.close();
  }
  std::vector<char>().swap(faces_);
  if (reason_.empty())
    return true;
  if (created_) {
    std::error_code ignored;
    std::filesystem::remove(output_, ignored);
  }
  error = output_ + ": " + reason_;
  return false;
}

bool writePlyFromInput(const std::string &output, const std::string &input,
                       const BinaryCloudLayout &layout,
                       const std::vector<std::array<std::uint32_t, 3>> &triangles,
                       std::string &error) {
  PlyFromInputWriter writer;
  if (writer.open(output, input, layout, triangles.size())) {
    constexpr std::size_t block = std::size_t(1) << 20;
    for (std::size_t begin = 0; begin < triangles.size(); begin += block)
      writer.add(triangles.data() + begin, std::min(block, triangles.size() - begin));
  }
  return writer.close(error);
}

} // namespace pcl_ms_mpi
