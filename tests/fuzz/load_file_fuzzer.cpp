// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for one file reader of pcl_ms/io.h. The bytes are written
// to a file with the extension this target was built for
// (PCL_MS_FUZZ_EXTENSION) and read with loadPointCloud (PCL_MS_FUZZ_MESH 0)
// or loadMesh (1). The readers must return true or false with a reason,
// never crash, hang or hand back data that contradicts what they promise.
#include "fuzz_bytes.h"

#include <pcl_ms/io.h>

#include <cstdint>
#include <cstdlib>
#include <string>

namespace {

using pcl_ms_fuzz::broken;

#if !PCL_MS_FUZZ_MESH
void checkCloud(const pcl::PCLPointCloud2 &cloud) {
  if (cloud.width * std::uint64_t{cloud.height} == 0)
    broken("a loaded cloud has at least one point");
  if (cloud.data.size() != std::uint64_t{cloud.row_step} * cloud.height ||
      cloud.row_step != std::uint64_t{cloud.point_step} * cloud.width)
    broken("the cloud's data matches its layout");
  for (const char *name : {"x", "y", "z"}) {
    bool found = false;
    for (const pcl::PCLPointField &field : cloud.fields)
      found = found || (field.name == name && field.datatype == pcl::PCLPointField::FLOAT32 &&
                        field.offset + 4u <= cloud.point_step);
    if (!found)
      broken("a loaded cloud has float fields x, y and z inside each point");
  }
}
#else
void checkMesh(const std::vector<Eigen::Vector3d> &vertices,
               const std::vector<pcl_ms::Triangle> &triangles) {
  if (triangles.empty())
    broken("a loaded mesh has faces");
  for (const pcl_ms::Triangle &triangle : triangles)
    for (pcl_ms::VertexIndex v : triangle)
      if (v >= vertices.size())
        broken("every face indexes a vertex");
}
#endif

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  const pcl_ms_fuzz::ScratchFile scratch(PCL_MS_FUZZ_EXTENSION, data, size);
  std::string error;
#if PCL_MS_FUZZ_MESH
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  if (pcl_ms::loadMesh(scratch.path(), vertices, triangles, error))
    checkMesh(vertices, triangles);
  else if (error.empty())
    broken("a failed load says why");
#else
  pcl::PCLPointCloud2 cloud;
  if (pcl_ms::loadPointCloud(scratch.path(), cloud, error))
    checkCloud(cloud);
  else if (error.empty())
    broken("a failed load says why");
#endif
  return 0;
}
