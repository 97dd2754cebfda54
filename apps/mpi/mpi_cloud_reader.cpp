// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpi_cloud_reader.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace pcl_ms_mpi {
namespace {

// A header longer than this is not one this reader needs to understand.
constexpr std::size_t max_header_lines = 64, max_header_line = 4096;

bool parseCount(const std::string &word, std::uint64_t &value) {
  if (word.empty() || word.size() > 19 ||
      !std::all_of(word.begin(), word.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return false;
  value = std::stoull(word);
  return true;
}

std::vector<std::string> words(const std::string &line) {
  std::istringstream stream(line);
  std::vector<std::string> found;
  for (std::string word; stream >> word;)
    found.push_back(word);
  return found;
}

bool littleEndianHost() {
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

} // namespace

bool describeBinaryPcd(const std::string &path, BinaryCloudLayout &layout, std::string &fields) {
  if (!littleEndianHost()) // PCD binary data is the writer's memory: little-endian in practice
    return false;
  std::error_code code;
  const std::uintmax_t size = std::filesystem::file_size(path, code);
  if (code)
    return false;
  std::ifstream in(path, std::ios::binary);
  std::vector<std::string> names, sizes, types, counts;
  std::uint64_t width = 0, height = 1, points = 0;
  bool has_width = false, has_points = false, has_data = false;
  std::array<float, 3> origin = {0, 0, 0};
  std::string line;
  for (std::size_t n = 0; !has_data; ++n) {
    if (n == max_header_lines || !std::getline(in, line) || line.size() > max_header_line)
      return false;
    const std::vector<std::string> w = words(line);
    if (w.empty() || w[0][0] == '#')
      continue;
    const std::vector<std::string> values(w.begin() + 1, w.end());
    if (w[0] == "VERSION") {
      continue;
    } else if (w[0] == "FIELDS") {
      names = values;
    } else if (w[0] == "SIZE") {
      sizes = values;
    } else if (w[0] == "TYPE") {
      types = values;
    } else if (w[0] == "COUNT") {
      counts = values;
    } else if (w[0] == "WIDTH" && values.size() == 1) {
      has_width = parseCount(values[0], width);
    } else if (w[0] == "HEIGHT" && values.size() == 1) {
      if (!parseCount(values[0], height))
        return false;
    } else if (w[0] == "POINTS" && values.size() == 1) {
      has_points = parseCount(values[0], points);
    } else if (w[0] == "VIEWPOINT" && values.size() == 7) {
      for (int k = 0; k < 3; ++k) {
        char *end = nullptr;
        origin[k] = std::strtof(values[k].c_str(), &end);
        if (*end != '\0' || !std::isfinite(origin[k]))
          return false;
      }
    } else if (w[0] == "DATA" && values.size() == 1 && values[0] == "binary") {
      has_data = true;
    } else {
      return false;
    }
  }
  if (names.empty() || sizes.size() != names.size() || types.size() != names.size() ||
      (!counts.empty() && counts.size() != names.size()) || !has_width || !has_points ||
      points == 0 || width > UINT32_MAX || height > UINT32_MAX || width * height != points ||
      points >= UINT32_MAX)
    return false;
  BinaryCloudLayout found;
  std::array<int, 3> xyz = {-1, -1, -1};
  std::uint64_t offset = 0;
  for (std::size_t f = 0; f < names.size(); ++f) {
    std::uint64_t bytes = 0, count = 1;
    if (!parseCount(sizes[f], bytes) || (bytes != 1 && bytes != 2 && bytes != 4 && bytes != 8) ||
        (!counts.empty() && (!parseCount(counts[f], count) || count == 0 || count > 1000000)) ||
        (types[f] != "F" && types[f] != "I" && types[f] != "U"))
      return false;
    const bool single_float = types[f] == "F" && bytes == 4 && count == 1;
    static const char *const axes[3] = {"x", "y", "z"};
    static const char *const normals[3] = {"normal_x", "normal_y", "normal_z"};
    for (int k = 0; k < 3; ++k) {
      if (names[f] == axes[k]) {
        if (!single_float || xyz[k] >= 0)
          return false;
        xyz[k] = static_cast<int>(offset);
      }
      if (names[f] == normals[k] && single_float)
        found.normal[k] = static_cast<std::int32_t>(offset);
    }
    offset += bytes * count;
  }
  // More records than the file could hold: rank 0's guarded loader reports
  // it, and record offsets below cannot overflow.
  if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0 || points > size / offset)
    return false;
  found.data_offset = static_cast<std::uint64_t>(in.tellg());
  found.points = points;
  found.record_bytes = offset;
  found.file_size = size;
  found.width = static_cast<std::uint32_t>(width);
  found.height = static_cast<std::uint32_t>(height);
  for (int k = 0; k < 3; ++k)
    found.xyz[k] = static_cast<std::uint32_t>(xyz[k]);
  found.xyz_only = names.size() == 3 && offset == 12 && xyz[0] == 0 && xyz[1] == 4 && xyz[2] == 8;
  found.origin = origin;
  layout = found;
  fields.clear();
  for (const std::string &name : names)
    fields += (fields.empty() ? "" : " ") + name;
  return true;
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
    error = path + ": truncated PCD file: points " + std::to_string(begin) + " to " +
            std::to_string(end) + " need bytes " + std::to_string(first) + " to " +
            std::to_string(last) + ", the file ends at byte " + std::to_string(size);
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

bool writePlyFromInput(const std::string &output, const std::string &input,
                       const BinaryCloudLayout &layout,
                       const std::vector<std::array<std::uint32_t, 3>> &triangles,
                       std::string &error) {
  std::string reason;
  bool created = false;
  {
    std::ofstream out(output, std::ios::binary | std::ios::trunc);
    if (!out) {
      reason = std::string("cannot open for writing: ") + std::strerror(errno);
    } else {
      created = true;
      // The header pcl::io::savePLYFileBinary writes for such a mesh.
      out << "ply\nformat binary_little_endian 1.0\ncomment PCL generated\nelement vertex "
          << layout.points
          << "\nproperty float x\nproperty float y\nproperty float z\nelement face "
          << triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
      // The vertex block is the input's x y z records as they are.
      constexpr std::uint64_t block = std::uint64_t(1) << 20;
      std::vector<unsigned char> bytes;
      for (std::uint64_t begin = 0; begin < layout.points && reason.empty(); begin += block) {
        const std::uint64_t end = std::min(layout.points, begin + block);
        if (!readRecords(input, layout, begin, end, bytes, reason))
          break;
        out.write(reinterpret_cast<const char *>(bytes.data()),
                  static_cast<std::streamsize>(bytes.size()));
      }
      std::vector<char> faces;
      for (std::size_t begin = 0; begin < triangles.size() && reason.empty(); begin += block) {
        const std::size_t end = std::min<std::size_t>(triangles.size(), begin + block);
        faces.resize((end - begin) * 13);
        char *at = faces.data();
        for (std::size_t t = begin; t < end; ++t) {
          *at++ = 3;
          std::memcpy(at, triangles[t].data(), 12);
          at += 12;
        }
        out.write(faces.data(), static_cast<std::streamsize>(faces.size()));
      }
      out.flush();
      if (reason.empty() && !out)
        reason = std::string("write failed: ") + std::strerror(errno);
    }
  }
  if (reason.empty())
    return true;
  if (created) {
    std::error_code ignored;
    std::filesystem::remove(output, ignored);
  }
  error = output + ": " + reason;
  return false;
}

} // namespace pcl_ms_mpi
