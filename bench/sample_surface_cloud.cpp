// SPDX-License-Identifier: GPL-3.0-or-later
// sample_surface_cloud: writes a uniform random sampling of a mesh as a
// binary PCD, the same points bench_buckets meshes in memory (seed 20241122
// + size by default), so that the command-line tools can be timed on them.
#include "surface_sampling.h"
#include "tool_support.h"

#include <pcl_ms/io.h>

#include <pcl/console/parse.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cstdio>
#include <string>
#include <vector>

namespace {

using pcl_ms_tools::fail;

int run(int argc, char **argv) {
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i)
    if (argv[i][0] != '-' && (i == 1 || std::string(argv[i - 1]) != "-seed"))
      positional.emplace_back(argv[i]);
  if (positional.size() != 3 || pcl_ms::fileExtension(positional[2]) != ".pcd") {
    std::fprintf(stderr,
                 "Usage: %s mesh points output.pcd [-seed S]\n"
                 "  S defaults to 20241122 + points (bench_buckets' sampling)\n",
                 argv[0]);
    return pcl_ms_tools::kBadArguments;
  }
  std::size_t count = 0;
  try {
    count = std::stoull(positional[1]);
  } catch (const std::exception &) {
    return fail(pcl_ms_tools::kBadArguments, "'" + positional[1] + "' is not a point count");
  }
  unsigned int seed = 20241122u + static_cast<unsigned int>(count);
  if (pcl::console::find_argument(argc, argv, "-seed") >= 0 &&
      pcl::console::parse_argument(argc, argv, "-seed", seed) < 0)
    return fail(pcl_ms_tools::kBadArguments, "-seed needs a number");

  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  std::string error;
  if (!pcl_ms::loadMesh(positional[0], vertices, triangles, error))
    return fail(pcl_ms_tools::kIoFailure, error);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  cloud.reserve(count);
  for (const Eigen::Vector3f &p : pcl_ms_tools::sampleSurface(vertices, triangles, count, seed))
    cloud.push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  if (pcl::io::savePCDFileBinary(positional[2], cloud) != 0)
    return fail(pcl_ms_tools::kIoFailure, positional[2] + ": cannot write");
  std::printf("%zu points from %s (seed %u) written to %s\n", count, positional[0].c_str(), seed,
              positional[2].c_str());
  return pcl_ms_tools::kSuccess;
}

} // namespace

int main(int argc, char **argv) {
  return pcl_ms_tools::runGuarded(run, argc, argv, pcl_ms_tools::kIoFailure);
}
