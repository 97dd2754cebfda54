// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the MPI tool's reading in parts (apps/mpi/
// mpi_cloud_reader.h): the first byte picks .pcd or .ply, the rest is the
// file. Whatever the header says, a layout that is accepted must place x, y,
// z (and the normals) inside each record; three ranks' byte ranges must
// each be read whole or refused with a reason; and a file read whole in
// parts must be one the ordinary reader (pcl_ms::loadPointCloud) accepts,
// with the same points and normals (none where it has none), bit for bit,
// and the same width and height: ranks and one process mesh the same cloud
// from the same viewpoint.
#include "fuzz_bytes.h"
#include "mpi_cloud_reader.h"

#include <pcl_ms/io.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace pcl_ms_fuzz {

namespace {

/// The offset of float field `name` in the ordinary reader's cloud, or -1.
int floatFieldOffset(const pcl::PCLPointCloud2 &cloud, const char *name) {
  for (const pcl::PCLPointField &field : cloud.fields)
    if (field.name == name && field.datatype == pcl::PCLPointField::FLOAT32 && field.count == 1)
      return static_cast<int>(field.offset);
  return -1;
}

std::uint32_t floatBits(const std::uint8_t *at) {
  std::uint32_t bits;
  std::memcpy(&bits, at, sizeof bits);
  return bits;
}

} // namespace

/// The target's body (see PCL_MS_FUZZ_TARGET).
inline int binaryLayoutOneInput(const std::uint8_t *data, std::size_t size) {
  const bool ply = size > 0 && (data[0] & 1);
  const ScratchFile scratch(ply ? ".ply" : ".pcd", data + (size > 0), size - (size > 0));
  const std::string &path = scratch.path();
  pcl_ms_mpi::BinaryCloudLayout layout;
  std::string fields;
  if (!pcl_ms_mpi::describeBinaryCloud(path, layout, fields))
    return 0; // left to the ordinary reader
  const std::uint64_t record = layout.record_bytes;
  if (record < 12 || layout.ply != (ply ? 1 : 0) || layout.data_offset > layout.file_size)
    broken("an accepted layout has records of three floats at least, in the file");
  for (int k = 0; k < 3; ++k)
    if (layout.xyz[k] + std::uint64_t{4} > record ||
        (layout.normal[k] >= 0 && layout.normal[k] + std::uint64_t{4} > record))
      broken("x, y, z and the normals lie inside each record");
  if (layout.points > layout.file_size / record)
    broken("no more records than the file could hold");

  constexpr int ranks = 3;
  std::vector<std::uint8_t> all;
  bool whole = true;
  for (int rank = 0; rank < ranks; ++rank) {
    const std::uint64_t begin = pcl_ms_mpi::firstRecordOf(rank, ranks, layout.points);
    const std::uint64_t end = pcl_ms_mpi::firstRecordOf(rank + 1, ranks, layout.points);
    std::vector<unsigned char> bytes;
    std::string error;
    if (!pcl_ms_mpi::readRecords(path, layout, begin, end, bytes, error)) {
      if (error.empty())
        broken("a range that cannot be read says why");
      whole = false;
      continue;
    }
    if (bytes.size() != (end - begin) * record)
      broken("a range read is its records, all of them");
    all.insert(all.end(), bytes.begin(), bytes.end());
  }
  if (!whole || layout.points == 0)
    return 0;

  pcl::PCLPointCloud2 cloud;
  std::string error;
  if (!pcl_ms::loadPointCloud(path, cloud, error))
    broken("a file read whole in parts is one the ordinary reader accepts");
  if (std::uint64_t{cloud.width} * cloud.height != layout.points)
    broken("the ordinary reader finds as many points");
  if (cloud.width != layout.width || cloud.height != layout.height)
    broken("the ordinary reader sees the same rows (an organized cloud has a viewpoint)");
  if (pcl_ms::hasNormals(cloud) != layout.hasNormals())
    broken("normals are read in parts exactly when the ordinary reader has them");
  const int axes[3] = {floatFieldOffset(cloud, "x"), floatFieldOffset(cloud, "y"),
                       floatFieldOffset(cloud, "z")};
  const int normals[3] = {floatFieldOffset(cloud, "normal_x"), floatFieldOffset(cloud, "normal_y"),
                          floatFieldOffset(cloud, "normal_z")};
  for (std::uint64_t i = 0; i < layout.points; ++i)
    for (int k = 0; k < 3; ++k) {
      const std::uint8_t *point = &cloud.data[i * cloud.point_step];
      if (axes[k] < 0 || floatBits(point + axes[k]) != floatBits(&all[i * record + layout.xyz[k]]))
        broken("the points read in parts are the ordinary reader's, bit for bit");
      // The tool reads normals in parts only when all three are there.
      if (layout.hasNormals() &&
          (normals[k] < 0 ||
           floatBits(point + normals[k]) !=
               floatBits(&all[i * record + static_cast<std::uint32_t>(layout.normal[k])])))
        broken("the normals read in parts are the ordinary reader's, bit for bit");
    }
  return 0;
}

} // namespace pcl_ms_fuzz

PCL_MS_FUZZ_TARGET(pcl_ms_fuzz::binaryLayoutOneInput)
