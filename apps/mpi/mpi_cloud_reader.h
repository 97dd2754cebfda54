// SPDX-License-Identifier: GPL-3.0-or-later
// Reading one binary PCD or PLY file across the ranks of an MPI job: rank 0
// reads the header, every rank reads the records of its own byte range, and
// the ranks then share them (docs/algorithm.md, "Across processes"). Files
// this does not recognise (ASCII or compressed PCD, ASCII or big-endian PLY,
// the other formats) are left to rank 0's ordinary reader, which checks them
// in full.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace pcl_ms_mpi {

/// Where the points of a binary PCD or PLY file are. Plain data: rank 0 fills it
/// and broadcasts it as bytes.
struct BinaryCloudLayout {
  std::uint64_t data_offset = 0; // the first record's byte
  std::uint64_t points = 0;
  std::uint64_t record_bytes = 0;
  std::uint64_t file_size = 0;
  std::uint32_t width = 0, height = 0;
  std::array<std::uint32_t, 3> xyz = {0, 0, 0};      // byte offsets of x, y, z in a record
  std::array<std::int32_t, 3> normal = {-1, -1, -1}; // normal_x, _y, _z, or -1
  std::int32_t xyz_only = 0;                         // fields are exactly x y z (12 bytes)
  std::array<float, 3> origin = {0, 0, 0};           // VIEWPOINT translation
  std::int32_t ply = 0;                              // a PLY file, not a PCD
  bool hasNormals() const { return normal[0] >= 0 && normal[1] >= 0 && normal[2] >= 0; }
};

/// True when `path` is a binary cloud this reader understands, read in parts:
/// - a PCD file (`.pcd`) with DATA binary, whose x, y and z (and normal_x,
///   normal_y, normal_z, if present) are single 4-byte floats;
/// - a binary_little_endian PLY file (`.ply`) whose first element is the
///   vertices, of fixed-size properties only, among them single floats x, y
///   and z (normals, as nx or normal_x..., used if present), followed by
///   fixed-size elements only (a cloud, not a mesh with faces). The camera
///   element's viewport gives an organized cloud its rows, as PCL's reader
///   does. Files with obj_info lines or a range_grid, which PCL's reader
///   also reshapes, are not read in parts.
/// `fields` gets the field names. False otherwise: the caller then reads
/// the file the ordinary way, which gives the precise error for a bad
/// header.
bool describeBinaryCloud(const std::string &path, BinaryCloudLayout &layout, std::string &fields);

/// The records [begin, end) of rank `rank`'s byte range: `end - begin`
/// records of layout.record_bytes each. False, with the reason, when the
/// file does not hold them all (a truncated file).
bool readRecords(const std::string &path, const BinaryCloudLayout &layout, std::uint64_t begin,
                 std::uint64_t end, std::vector<unsigned char> &bytes, std::string &error);

/// The first record of rank `rank`'s share of `points` records.
inline std::uint64_t firstRecordOf(int rank, int ranks, std::uint64_t points) {
  return points * static_cast<std::uint64_t>(rank) / static_cast<std::uint64_t>(ranks);
}

/// Writes the mesh as pcl::io::savePLYFileBinary writes a PolygonMesh whose
/// cloud has the fields x y z only, byte for byte, taking the vertices from
/// the input file a block at a time instead of from a cloud in memory.
/// Triangles index the input's records. On failure no file is left.
bool writePlyFromInput(const std::string &output, const std::string &input,
                       const BinaryCloudLayout &layout,
                       const std::vector<std::array<std::uint32_t, 3>> &triangles,
                       std::string &error);

/// writePlyFromInput for triangles that come a piece at a time: open()
/// writes the header for `faces` triangles and the vertices, add() appends
/// triangles, close() ends the file. Once a step fails the others do
/// nothing and return false; close() then gives the reason and leaves no
/// file.
class PlyFromInputWriter {
public:
  bool open(const std::string &output, const std::string &input, const BinaryCloudLayout &layout,
            std::uint64_t faces);
  bool add(const std::array<std::uint32_t, 3> *triangles, std::size_t count);
  bool close(std::string &error);

private:
  std::ofstream out_;
  std::string output_, reason_;
  bool created_ = false;
  std::vector<char> faces_; // one piece's bytes
};

} // namespace pcl_ms_mpi
