// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh readers for .ply, .obj, .off and legacy .vtk (see mesh_readers.h),
// and loadMesh() on top of them and the STL reader (mesh_file.h).
#include "mesh_readers.h"

#include "io_parsing.h"

#include <pcl_ms/mesh_file.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string_view>

namespace pcl_ms {
namespace io_detail {
namespace {

/// Reads PLY values one at a time from an in-memory body, either format.
class PlyValueReader {
public:
  PlyValueReader(std::string_view body, PlyFormat format)
      : body_(body), format_(format),
        swap_(format != PlyFormat::Ascii &&
              (format == PlyFormat::BinaryLittleEndian) != hostIsLittleEndian()) {}

  bool read(PlyType type, double &value) {
    if (format_ == PlyFormat::Ascii) {
      while (position_ < body_.size() && isBlank(body_[position_]))
        ++position_;
      const std::size_t start = position_;
      while (position_ < body_.size() && !isBlank(body_[position_]))
        ++position_;
      const std::string_view token = body_.substr(start, position_ - start);
      // A float property holds what a binary file would: the text rounded
      // once to float, so ASCII and binary copies match position for position.
      if (type == PlyType::Float32) {
        float single;
        if (!parseNumber(token, single))
          return false;
        value = single;
        return true;
      }
      return parseDouble(token, value);
    }
    const std::size_t size = plyTypeSize(type);
    if (position_ + size > body_.size())
      return false;
    unsigned char raw[8];
    std::memcpy(raw, body_.data() + position_, size);
    position_ += size;
    if (swap_)
      std::reverse(raw, raw + size);
    value = decode(type, raw);
    return true;
  }

private:
  template <typename T> static double as(const unsigned char *raw) {
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return static_cast<double>(value);
  }

  static double decode(PlyType type, const unsigned char *raw) {
    switch (type) {
    case PlyType::Int8:
      return as<std::int8_t>(raw);
    case PlyType::UInt8:
      return as<std::uint8_t>(raw);
    case PlyType::Int16:
      return as<std::int16_t>(raw);
    case PlyType::UInt16:
      return as<std::uint16_t>(raw);
    case PlyType::Int32:
      return as<std::int32_t>(raw);
    case PlyType::UInt32:
      return as<std::uint32_t>(raw);
    case PlyType::Float32:
      return as<float>(raw);
    case PlyType::Float64:
      return as<double>(raw);
    }
    return 0;
  }

  std::string_view body_;
  PlyFormat format_;
  bool swap_;
  std::size_t position_ = 0;
};

// ---------------------------------------------------------------------------
// Meshes

/// Validates one polygon's corners and appends its fan triangulation. Pass
/// kUnknownVertexCount when the vertices are not all read yet and call
/// checkTriangleIndices() at the end.
bool addPolygon(const std::vector<std::int64_t> &corners, std::size_t vertex_count,
                std::vector<Triangle> &triangles, std::string &error) {
  if (corners.size() < 3) {
    error = "has fewer than 3 corners";
    return false;
  }
  for (std::int64_t corner : corners)
    if (corner < 0 || corner > std::numeric_limits<VertexIndex>::max() ||
        static_cast<std::uint64_t>(corner) >= vertex_count) {
      error = "references vertex " + std::to_string(corner) + " but there are " +
              std::to_string(vertex_count) + " vertices";
      return false;
    }
  for (std::size_t i = 1; i + 1 < corners.size(); ++i)
    triangles.push_back({static_cast<VertexIndex>(corners[0]), static_cast<VertexIndex>(corners[i]),
                         static_cast<VertexIndex>(corners[i + 1])});
  return true;
}

constexpr std::size_t kUnknownVertexCount = std::numeric_limits<std::size_t>::max();

/// Triangles of a strip (every other one flipped to keep the orientation).
bool addStrip(const std::int64_t *corners, std::size_t size, std::size_t vertex_count,
              std::vector<Triangle> &triangles, std::string &error) {
  std::vector<std::int64_t> triangle(3);
  for (std::size_t k = 0; k + 2 < size; ++k) {
    triangle = {corners[k], corners[k + 1], corners[k + 2]};
    if (triangle[0] == triangle[1] || triangle[1] == triangle[2] || triangle[0] == triangle[2])
      continue; // strips repeat a corner to turn; that triangle is not part of the surface
    if (k % 2 == 1)
      std::swap(triangle[0], triangle[1]);
    if (!addPolygon(triangle, vertex_count, triangles, error))
      return false;
  }
  return true;
}

/// Several strips in one list, separated by -1 (PLY "tristrips").
bool addStrips(const std::vector<std::int64_t> &corners, std::vector<Triangle> &triangles,
               std::string &error) {
  std::size_t start = 0;
  for (std::size_t i = 0; i <= corners.size(); ++i)
    if (i == corners.size() || corners[i] == -1) {
      if (!addStrip(corners.data() + start, i - start, kUnknownVertexCount, triangles, error))
        return false;
      start = i + 1;
    }
  return true;
}

bool checkTriangleIndices(std::size_t vertex_count, const std::vector<Triangle> &triangles,
                          std::string &error) {
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (VertexIndex corner : triangles[t])
      if (corner >= vertex_count) {
        error = "a face references vertex " + std::to_string(corner) + " but there are " +
                std::to_string(vertex_count) + " vertices";
        return false;
      }
  return true;
}

} // namespace

bool loadPlyMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error) {
  std::string bytes;
  if (!readFileBytes(path, bytes, error))
    return false;
  PlyHeader header;
  {
    std::istringstream in(bytes.substr(0, std::min<std::size_t>(bytes.size(), 1 << 20)));
    if (!parsePlyHeader(in, header, error) || !checkPlyBodySize(header, bytes.size(), error))
      return false;
  }
  PlyValueReader reader(std::string_view(bytes).substr(header.header_bytes), header.format);
  bool have_vertices = false, have_faces = false;
  std::vector<std::int64_t> corners;
  for (const PlyElement &element : header.elements) {
    if (have_vertices && have_faces)
      break;
    const bool is_vertex = element.name == "vertex";
    // "tristrips" lists triangle strips separated by -1 (used by some scanners).
    const bool is_strip = element.name == "tristrips";
    const bool is_face = element.name == "face" || is_strip;
    int x = -1, y = -1, z = -1, corner_list = -1;
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const std::string &name = element.properties[p].name;
      const bool is_list = element.properties[p].is_list;
      if (is_vertex && !is_list) {
        if (name == "x")
          x = static_cast<int>(p);
        else if (name == "y")
          y = static_cast<int>(p);
        else if (name == "z")
          z = static_cast<int>(p);
      }
      if (is_face && is_list && (name == "vertex_indices" || name == "vertex_index"))
        corner_list = static_cast<int>(p);
    }
    if (is_vertex && (x < 0 || y < 0 || z < 0)) {
      error = "the PLY vertex element lacks x, y or z";
      return false;
    }
    if (is_vertex)
      vertices.reserve(element.count);
    // Records without properties take no bytes: billions of them would be
    // a long loop that reads nothing (a fuzz finding).
    if (element.properties.empty())
      continue;

    for (std::uint64_t r = 0; r < element.count; ++r) {
      Eigen::Vector3d point = Eigen::Vector3d::Zero();
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty &property = element.properties[p];
        double value = 0;
        bool ok = reader.read(property.is_list ? property.count_type : property.value_type, value);
        if (ok && property.is_list) {
          const bool keep = static_cast<int>(p) == corner_list;
          if (!isWholeNumberIn(value, 0, 1e6)) {
            error = "corrupt PLY file: list of " + std::to_string(value) + " items in element '" +
                    element.name + "' record " + std::to_string(r);
            return false;
          }
          const auto length = static_cast<std::size_t>(value);
          if (keep)
            corners.clear();
          for (std::size_t i = 0; ok && i < length; ++i) {
            ok = reader.read(property.value_type, value);
            if (!ok || !keep)
              continue;
            // -1 separates triangle strips; anything else must be an index.
            if (!isWholeNumberIn(value, -1, std::numeric_limits<VertexIndex>::max())) {
              error = "corrupt PLY file: vertex index " + std::to_string(value) + " in element '" +
                      element.name + "' record " + std::to_string(r);
              return false;
            }
            corners.push_back(static_cast<std::int64_t>(value));
          }
        } else if (ok && is_vertex) {
          if (static_cast<int>(p) == x)
            point.x() = value;
          else if (static_cast<int>(p) == y)
            point.y() = value;
          else if (static_cast<int>(p) == z)
            point.z() = value;
        }
        if (!ok) {
          error = "truncated or malformed PLY data in element '" + element.name + "' record " +
                  std::to_string(r);
          return false;
        }
      }
      if (is_vertex)
        vertices.push_back(point);
      if (is_face && corner_list >= 0) {
        std::string reason;
        // Faces may precede the vertices in the file: indices are checked at the end.
        if (is_strip ? !addStrips(corners, triangles, reason)
                     : !addPolygon(corners, kUnknownVertexCount, triangles, reason)) {
          error = element.name + " " + std::to_string(r) + " " + reason;
          return false;
        }
      }
    }
    have_vertices = have_vertices || is_vertex;
    have_faces = have_faces || (is_face && corner_list >= 0);
  }
  if (!have_vertices) {
    error = "the PLY file has no vertex element";
    return false;
  }
  return checkTriangleIndices(vertices.size(), triangles, error);
}

bool loadObjMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error) {
  std::string bytes;
  if (!readFileBytes(path, bytes, error))
    return false;
  // Faces are checked once all vertices are known: OBJ allows forward references.
  std::vector<std::vector<std::int64_t>> faces;
  std::vector<std::size_t> face_lines;
  WordLines lines(bytes);
  while (lines.next()) {
    const std::vector<std::string_view> &words = lines.words();
    const std::string where = "line " + std::to_string(lines.lineNumber()) + ": ";
    if (words[0] == "v") {
      Eigen::Vector3d point;
      if (words.size() < 4 || !parseDouble(words[1], point.x()) ||
          !parseDouble(words[2], point.y()) || !parseDouble(words[3], point.z())) {
        error = where + "malformed vertex";
        return false;
      }
      vertices.push_back(point);
    } else if (words[0] == "f") {
      std::vector<std::int64_t> corners;
      for (std::size_t w = 1; w < words.size(); ++w) {
        // "v", "v/vt", "v//vn" or "v/vt/vn": only the vertex index matters.
        std::int64_t index = 0;
        if (!parseInteger(words[w].substr(0, words[w].find('/')), index) || index == 0) {
          error = where + "malformed face corner " + printable(words[w]);
          return false;
        }
        // Negative indices count back from the latest vertex.
        corners.push_back(index > 0 ? index - 1
                                    : static_cast<std::int64_t>(vertices.size()) + index);
      }
      faces.push_back(std::move(corners));
      face_lines.push_back(lines.lineNumber());
    }
    // Texture coordinates, normals, groups and materials are not needed.
  }
  for (std::size_t f = 0; f < faces.size(); ++f) {
    std::string reason;
    if (!addPolygon(faces[f], vertices.size(), triangles, reason)) {
      error = "line " + std::to_string(face_lines[f]) + ": face " + reason;
      return false;
    }
  }
  return true;
}

bool loadOffMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error) {
  std::string bytes;
  if (!readFileBytes(path, bytes, error))
    return false;
  // OFF is line oriented: one vertex or face per line, optionally followed by
  // colours, which is why tokens are not read as one flat stream.
  WordLines lines(bytes);
  const std::vector<std::string_view> &words = lines.words();

  if (!lines.next()) {
    error = "the file has no OFF header";
    return false;
  }
  static const char *variants[] = {"OFF",   "COFF",   "NOFF",   "CNOFF",
                                   "STOFF", "STCOFF", "STNOFF", "STCNOFF"};
  if (std::none_of(std::begin(variants), std::end(variants),
                   [&](const char *variant) { return words[0] == variant; })) {
    error = words[0].size() >= 3 && words[0].substr(words[0].size() - 3) == "OFF"
                ? "unsupported OFF variant " + printable(words[0])
                : "not an OFF file (first word is " + printable(words[0]) + ")";
    return false;
  }
  if (words.size() > 1 && words[1] == "BINARY") {
    error = "binary OFF files are not supported";
    return false;
  }
  // The counts follow the keyword on the same line or on the next one.
  std::size_t counts_at = 1;
  if (words.size() == 1) {
    if (!lines.next()) {
      error = "the OFF header has no vertex and face counts";
      return false;
    }
    counts_at = 0;
  }
  std::uint64_t vertex_count = 0, face_count = 0;
  if (words.size() < counts_at + 2 || !parseInteger(words[counts_at], vertex_count) ||
      !parseInteger(words[counts_at + 1], face_count)) {
    error = "line " + std::to_string(lines.lineNumber()) + ": malformed OFF counts";
    return false;
  }
  // Every vertex and face needs a line of at least a few bytes.
  if (static_cast<double>(vertex_count) + static_cast<double>(face_count) >
      static_cast<double>(bytes.size())) {
    error = "truncated OFF file: the counts exceed the file size";
    return false;
  }

  vertices.reserve(vertex_count);
  for (std::uint64_t v = 0; v < vertex_count; ++v) {
    Eigen::Vector3d point;
    if (!lines.next()) {
      error = "truncated OFF file: " + std::to_string(v) + " of " + std::to_string(vertex_count) +
              " vertices";
      return false;
    }
    if (words.size() < 3 || !parseDouble(words[0], point.x()) ||
        !parseDouble(words[1], point.y()) || !parseDouble(words[2], point.z())) {
      error = "line " + std::to_string(lines.lineNumber()) + ": malformed vertex";
      return false;
    }
    vertices.push_back(point);
  }
  std::vector<std::int64_t> corners;
  for (std::uint64_t f = 0; f < face_count; ++f) {
    if (!lines.next()) {
      error = "truncated OFF file: " + std::to_string(f) + " of " + std::to_string(face_count) +
              " faces";
      return false;
    }
    std::size_t size = 0;
    if (!parseInteger(words[0], size) || words.size() < size + 1) {
      error = "line " + std::to_string(lines.lineNumber()) + ": malformed face";
      return false;
    }
    corners.assign(size, 0);
    for (std::size_t i = 0; i < size; ++i)
      if (!parseInteger(words[i + 1], corners[i])) {
        error = "line " + std::to_string(lines.lineNumber()) + ": malformed face";
        return false;
      }
    std::string reason;
    if (!addPolygon(corners, vertices.size(), triangles, reason)) {
      error = "line " + std::to_string(lines.lineNumber()) + ": face " + reason;
      return false;
    }
  }
  return true;
}

namespace {

/// Legacy VTK reader for POLYDATA: POINTS plus POLYGONS and TRIANGLE_STRIPS,
/// ascii or (big-endian) binary, with both the classic cell layout and the
/// OFFSETS/CONNECTIVITY layout of file version 5.
class VtkReader {
public:
  explicit VtkReader(std::string_view bytes) : bytes_(bytes) {}

  bool read(std::vector<Eigen::Vector3d> &vertices, std::vector<Triangle> &triangles,
            std::string &error) {
    std::string_view line;
    if (!nextLine(line) || !startsWith(line, "# vtk DataFile")) {
      error = "not a legacy VTK file";
      return false;
    }
    if (!nextLine(line) || !nextLine(line)) { // title, then format
      error = "incomplete VTK header";
      return false;
    }
    if (trim(line) == "BINARY")
      binary_ = true;
    else if (trim(line) != "ASCII") {
      error = "VTK header: expected ASCII or BINARY, found " + printable(trim(line));
      return false;
    }
    if (!nextNonEmptyLine(line) ||
        splitWords(line) != std::vector<std::string_view>{"DATASET", "POLYDATA"}) {
      error = "only legacy VTK POLYDATA meshes are supported";
      return false;
    }
    bool have_points = false;
    while (nextNonEmptyLine(line)) {
      const std::vector<std::string_view> words = splitWords(line);
      const std::string_view key = words[0];
      if (key == "POINTS") {
        // A dataset has one point list: a second one would leave the cells
        // read so far indexing points it does not have.
        if (have_points) {
          error = "the VTK file has more than one POINTS section";
          return false;
        }
        if (!readPoints(words, vertices, error))
          return false;
        have_points = true;
      } else if (key == "POLYGONS" || key == "TRIANGLE_STRIPS" || key == "VERTICES" ||
                 key == "LINES") {
        if (!readCells(words, vertices.size(), key == "POLYGONS", key == "TRIANGLE_STRIPS",
                       triangles, error))
          return false;
      } else if (key == "POINT_DATA" || key == "CELL_DATA" || key == "FIELD" || key == "METADATA") {
        break; // attributes follow the geometry; nothing more to read
      } else {
        error = "unexpected VTK section " + printable(key);
        return false;
      }
    }
    if (!have_points) {
      error = "the VTK file has no POINTS";
      return false;
    }
    return true;
  }

private:
  bool nextLine(std::string_view &line) {
    if (position_ >= bytes_.size())
      return false;
    std::size_t end = bytes_.find('\n', position_);
    if (end == std::string_view::npos)
      end = bytes_.size();
    line = bytes_.substr(position_, end - position_);
    position_ = end + 1;
    return true;
  }

  bool nextNonEmptyLine(std::string_view &line) {
    while (nextLine(line))
      if (!trim(line).empty())
        return true;
    return false;
  }

  /// Reads `count` numbers of VTK type `type` into `out`.
  bool readValues(std::string_view type, std::uint64_t count, std::vector<double> &out,
                  std::string &error) {
    std::size_t size = 0;
    bool is_float = false, is_signed = true;
    if (type == "float")
      size = 4, is_float = true;
    else if (type == "double")
      size = 8, is_float = true;
    else if (type == "int" || type == "vtktypeint32")
      size = 4;
    else if (type == "unsigned_int" || type == "vtktypeuint32")
      size = 4, is_signed = false;
    else if (type == "long" || type == "vtktypeint64" || type == "vtkIdType")
      size = 8;
    else if (type == "unsigned_long" || type == "vtktypeuint64")
      size = 8, is_signed = false;
    else if (type == "short")
      size = 2;
    else if (type == "unsigned_short")
      size = 2, is_signed = false;
    else {
      error = "unsupported VTK data type " + printable(type);
      return false;
    }
    const double bytes_per_value = binary_ ? static_cast<double>(size) : 2.0;
    if (static_cast<double>(count) * bytes_per_value >
        static_cast<double>(bytes_.size() - std::min(position_, bytes_.size())) + 1) {
      error = "truncated VTK file";
      return false;
    }
    out.resize(count);
    for (std::uint64_t i = 0; i < count; ++i) {
      if (binary_) {
        if (position_ + size > bytes_.size()) {
          error = "truncated VTK file";
          return false;
        }
        unsigned char raw[8];
        std::memcpy(raw, bytes_.data() + position_, size);
        position_ += size;
        if (hostIsLittleEndian())
          std::reverse(raw, raw + size); // legacy binary VTK is big-endian
        out[i] = decode(raw, size, is_float, is_signed);
      } else {
        while (position_ < bytes_.size() && isBlank(bytes_[position_]))
          ++position_;
        const std::size_t start = position_;
        while (position_ < bytes_.size() && !isBlank(bytes_[position_]))
          ++position_;
        if (!parseDouble(bytes_.substr(start, position_ - start), out[i])) {
          error = start >= bytes_.size()
                      ? "truncated VTK file"
                      : "malformed VTK value " + printable(bytes_.substr(start, position_ - start));
          return false;
        }
      }
    }
    // Whatever remains of the line is read as an (empty) line by the caller.
    return true;
  }

  static double decode(const unsigned char *raw, std::size_t size, bool is_float, bool is_signed) {
    const auto get = [raw](auto value) {
      std::memcpy(&value, raw, sizeof(value));
      return static_cast<double>(value);
    };
    if (is_float)
      return size == 4 ? get(float()) : get(double());
    switch (size) {
    case 2:
      return is_signed ? get(std::int16_t()) : get(std::uint16_t());
    case 4:
      return is_signed ? get(std::int32_t()) : get(std::uint32_t());
    default:
      return is_signed ? get(std::int64_t()) : get(std::uint64_t());
    }
  }

  bool readPoints(const std::vector<std::string_view> &words,
                  std::vector<Eigen::Vector3d> &vertices, std::string &error) {
    std::uint64_t count = 0;
    if (words.size() != 3 || !parseInteger(words[1], count)) {
      error = "malformed VTK POINTS line";
      return false;
    }
    std::vector<double> values;
    if (!readValues(words[2], 3 * count, values, error))
      return false;
    vertices.resize(count);
    for (std::uint64_t i = 0; i < count; ++i)
      vertices[i] = Eigen::Vector3d(values[3 * i], values[3 * i + 1], values[3 * i + 2]);
    return true;
  }

  bool readCells(const std::vector<std::string_view> &words, std::size_t vertex_count,
                 bool polygons, bool strips, std::vector<Triangle> &triangles, std::string &error) {
    std::uint64_t cell_count = 0, total = 0;
    if (words.size() != 3 || !parseInteger(words[1], cell_count) ||
        !parseInteger(words[2], total)) {
      error = "malformed VTK " + std::string(words[0]) + " line";
      return false;
    }
    // Build (offsets, connectivity) from whichever layout the file uses.
    std::vector<double> offsets, connectivity;
    const std::size_t saved = position_;
    std::string_view line;
    if (nextNonEmptyLine(line) && startsWith(trim(line), "OFFSETS")) {
      const std::vector<std::string_view> offset_words = splitWords(line);
      if (offset_words.size() != 2) {
        error = "malformed VTK OFFSETS line";
        return false;
      }
      if (!readValues(offset_words[1], cell_count, offsets, error))
        return false;
      if (!nextNonEmptyLine(line) || !startsWith(trim(line), "CONNECTIVITY")) {
        error = "VTK OFFSETS without CONNECTIVITY";
        return false;
      }
      const std::vector<std::string_view> connectivity_words = splitWords(line);
      if (connectivity_words.size() != 2) {
        error = "malformed VTK CONNECTIVITY line";
        return false;
      }
      if (!readValues(connectivity_words[1], total, connectivity, error))
        return false;
    } else {
      position_ = saved;
      std::vector<double> cells;
      if (!readValues("int", total, cells, error))
        return false;
      offsets.push_back(0);
      std::size_t at = 0;
      for (std::uint64_t c = 0; c < cell_count; ++c) {
        if (at >= cells.size() || !isWholeNumberIn(cells[at], 0, cells.size() - at - 1)) {
          error = "corrupt VTK cell list";
          return false;
        }
        const auto size = static_cast<std::size_t>(cells[at]);
        connectivity.insert(connectivity.end(), cells.begin() + at + 1,
                            cells.begin() + at + 1 + size);
        at += size + 1;
        offsets.push_back(static_cast<double>(connectivity.size()));
      }
    }
    if (!polygons && !strips)
      return true;
    // Values are read as doubles; anything not a whole number in range would
    // make the integer conversions below undefined.
    for (double corner : connectivity)
      if (!isWholeNumberIn(corner, 0, static_cast<double>(vertex_count) - 1)) {
        error = "VTK cell references vertex " + printableNumber(corner) + " but there are " +
                std::to_string(vertex_count) + " vertices";
        return false;
      }
    std::vector<std::int64_t> corners;
    for (std::size_t c = 0; c + 1 < offsets.size(); ++c) {
      if (!isWholeNumberIn(offsets[c], 0, static_cast<double>(connectivity.size())) ||
          !isWholeNumberIn(offsets[c + 1], offsets[c], static_cast<double>(connectivity.size()))) {
        error = "corrupt VTK cell offsets";
        return false;
      }
      corners.assign(connectivity.begin() + static_cast<std::ptrdiff_t>(offsets[c]),
                     connectivity.begin() + static_cast<std::ptrdiff_t>(offsets[c + 1]));
      std::string reason;
      if (polygons && !addPolygon(corners, vertex_count, triangles, reason)) {
        error = "VTK polygon " + std::to_string(c) + " " + reason;
        return false;
      }
      if (strips && !addStrip(corners.data(), corners.size(), vertex_count, triangles, reason)) {
        error = "VTK triangle strip " + std::to_string(c) + " " + reason;
        return false;
      }
    }
    return true;
  }

  std::string_view bytes_;
  std::size_t position_ = 0;
  bool binary_ = false;
};

} // namespace

bool loadVtkMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error) {
  std::string bytes;
  if (!readFileBytes(path, bytes, error))
    return false;
  return VtkReader(bytes).read(vertices, triangles, error);
}

bool readMeshFile(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                  std::vector<Triangle> &triangles, std::string &reason) {
  const std::string extension = fileExtension(path);
  if (extension == ".ply")
    return loadPlyMesh(path, vertices, triangles, reason);
  if (extension == ".obj")
    return loadObjMesh(path, vertices, triangles, reason);
  if (extension == ".off")
    return loadOffMesh(path, vertices, triangles, reason);
  if (extension == ".vtk")
    return loadVtkMesh(path, vertices, triangles, reason);
  if (extension == ".stl")
    return loadStlMesh(path, vertices, triangles, reason);
  reason = unknownFormat(extension, "mesh", ".ply, .obj, .off, .vtk or .stl");
  return false;
}

} // namespace io_detail

std::string fileExtension(const std::string &path) {
  return io_detail::toLower(std::filesystem::path(path).extension().string());
}

bool loadMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
              std::vector<Triangle> &triangles, std::string &error) {
  vertices.clear();
  triangles.clear();
  std::string reason;
  bool ok = false;
  try {
    std::uintmax_t size = 0;
    ok = io_detail::checkInputFile(path, size, reason) &&
         io_detail::readMeshFile(path, vertices, triangles, reason);
    if (ok && triangles.empty()) {
      reason = "the file contains no faces";
      ok = false;
    }
  } catch (const std::exception &exception) {
    reason = std::string("unexpected failure: ") + exception.what();
    ok = false;
  }
  if (!ok) {
    vertices.clear();
    triangles.clear();
    error = path + ": " + reason;
  }
  return ok;
}

} // namespace pcl_ms
