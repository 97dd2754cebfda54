// SPDX-License-Identifier: GPL-3.0-or-later
//
// Writes the clouds of known topology and non-uniform density
// (src/tools/synthetic_clouds.h) as binary PCD files, the scans organized
// and with their sensor pose in the VIEWPOINT field, and truth.csv with what
// a correct reconstruction of each has. scripts/topology_table.sh meshes them.
#include "mesh_report.h"
#include "synthetic_clouds.h"
#include "tool_support.h"

#include <pcl/console/parse.h>
#include <pcl/io/pcd_io.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

using pcl_ms_tools::fail;
using pcl_ms_tools::kBadArguments;
using pcl_ms_tools::kIoFailure;

void printHelp(const char *program) {
  std::printf("usage: %s [-out DIR] [-seed N] [-scan_size W,H]\n"
              "  -out DIR         output directory, created if missing (default synthetic_clouds)\n"
              "  -seed N          seed of every generator (default %llu)\n"
              "  -scan_size W,H   pixels of the box-on-plane scans (default 160,120)\n"
              "Writes DIR/<name>.pcd (binary) for each cloud and DIR/truth.csv with the columns\n"
              "name, file, points, components, boundary_loops, euler_characteristic, orientable,\n"
              "density_law; points counts the finite points.\n",
              program, static_cast<unsigned long long>(pcl_ms_tools::kSyntheticSeed));
}

std::size_t finiteCount(const pcl::PointCloud<pcl::PointXYZ> &cloud) {
  std::size_t finite = 0;
  for (const pcl::PointXYZ &p : cloud)
    finite += std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
  return finite;
}

int run(int argc, char **argv) {
  if (pcl::console::find_switch(argc, argv, "-h")) {
    printHelp(argv[0]);
    return 0;
  }
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument != "-out" && argument != "-seed" && argument != "-scan_size")
      return fail(kBadArguments, "unknown argument '" + argument + "' (see -h)");
    if (++i >= argc)
      return fail(kBadArguments, argument + " needs a value");
  }
  std::string out_dir = "synthetic_clouds", seed_text;
  pcl::console::parse_argument(argc, argv, "-out", out_dir);
  std::uint64_t seed = pcl_ms_tools::kSyntheticSeed;
  if (pcl::console::parse_argument(argc, argv, "-seed", seed_text) >= 0) {
    std::size_t used = 0;
    try {
      seed = std::stoull(seed_text, &used);
    } catch (const std::exception &) {
      used = 0;
    }
    if (used == 0 || used != seed_text.size())
      return fail(kBadArguments,
                  "-seed: expected a non-negative whole number, got '" + seed_text + "'");
  }
  int scan_width = 160, scan_height = 120;
  if (pcl::console::find_argument(argc, argv, "-scan_size") >= 0 &&
      (pcl::console::parse_2x_arguments(argc, argv, "-scan_size", scan_width, scan_height) < 0 ||
       scan_width < 2 || scan_height < 2))
    return fail(kBadArguments, "-scan_size: expected two numbers of at least 2, e.g. 640,480");

  std::error_code error;
  std::filesystem::create_directories(out_dir, error);
  if (error)
    return fail(kIoFailure, "cannot create " + out_dir + ": " + error.message());
  const std::string truth_path = (std::filesystem::path(out_dir) / "truth.csv").string();
  std::ofstream truth(truth_path);
  if (!truth)
    return fail(kIoFailure, "cannot write " + truth_path);
  truth << "name,file,points,components,boundary_loops,euler_characteristic,orientable,"
           "density_law\n";

  for (const pcl_ms_tools::SyntheticCloud &synthetic :
       pcl_ms_tools::syntheticClouds(seed, scan_width, scan_height)) {
    const std::string file = synthetic.name + ".pcd";
    const std::string path = (std::filesystem::path(out_dir) / file).string();
    if (pcl::io::savePCDFileBinary(path, synthetic.cloud) != 0)
      return fail(kIoFailure, "cannot write " + path);
    const std::size_t points = finiteCount(synthetic.cloud);
    const pcl_ms_tools::KnownTopology &t = synthetic.truth;
    truth << synthetic.name << ',' << file << ',' << points << ',' << t.components << ','
          << t.boundary_loops << ',' << t.euler_characteristic << ',' << (t.orientable ? 1 : 0)
          << ',' << pcl_ms_tools::csvField(synthetic.density_law) << '\n';
    std::printf("%-28s %8s points  %s\n", file.c_str(), pcl_ms_tools::withThousands(points).c_str(),
                synthetic.density_law.c_str());
  }
  if (!truth.flush())
    return fail(kIoFailure, "cannot write " + truth_path);
  std::printf("truth: %s\n", truth_path.c_str());
  return 0;
}

} // namespace

int main(int argc, char **argv) { return pcl_ms_tools::runGuarded(run, argc, argv, kIoFailure); }
