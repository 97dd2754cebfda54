// SPDX-License-Identifier: GPL-3.0-or-later
// pcl_ms_reconstruct: meshes a point cloud file with
// pcl::MedialScaffoldReconstruction and saves the mesh, in the manner of
// PCL's own command-line tools. On any failure it prints exactly one line,
// "error: <reason>", on stderr and exits non-zero, so scripts can rely on it.
#include "huge_page_heap.h"
#include "reconstruct_cli.h"
#include "tool_support.h"

#include <pcl_ms/medial_scaffold_reconstruction.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace {

using pcl::console::print_info;
using pcl::console::print_value;
using pcl_ms_tools::fail;
using pcl_ms_tools::kBadArguments;
using pcl_ms_tools::kReconstructionFailure;
using pcl_ms_tools::kSuccess;
using pcl_ms_tools::SilencePclMessages;

/// Converts the cloud to PointT, meshes it and returns the polygons, which
/// index the cloud's points directly.
template <typename PointT>
bool reconstructAs(const pcl::PCLPointCloud2 &cloud, const pcl_ms::Parameters &parameters,
                   const std::vector<pcl::Vertices> &initial, std::vector<pcl::Vertices> &polygons,
                   pcl_ms::Result &result, std::string &error) {
  auto points = pcl::make_shared<pcl::PointCloud<PointT>>();
  pcl::fromPCLPointCloud2(cloud, *points);
  pcl::MedialScaffoldReconstruction<PointT> reconstruction;
  reconstruction.setInputCloud(points);
  reconstruction.setParameters(parameters);
  reconstruction.setInitialTriangles(initial);
  reconstruction.setUseSensorOrigin(false); // run() decided the viewpoint
  pcl::PolygonMesh mesh;
  {
    SilencePclMessages silence;
    reconstruction.reconstruct(mesh);
  }
  if (!reconstruction.getErrorMessage().empty()) {
    error = "reconstruction failed: " + reconstruction.getErrorMessage();
    return false;
  }
  polygons = std::move(mesh.polygons);
  result = reconstruction.getResult();
  return true;
}

int run(int argc, char **argv) {
  pcl_ms_tools::ReconstructOptions options;
  std::string error;
  if (!pcl_ms_tools::parseReconstructArguments(argc, argv, options, error))
    return fail(kBadArguments, error);
  if (options.help) {
    pcl_ms_tools::printReconstructHelp(
        argv[0], "Meshes a point cloud by greedy gap transforms on its medial scaffold.");
    return kSuccess;
  }

  pcl_ms::Parameters parameters;
  if (const std::string reason = pcl_ms_tools::reconstructParameters(options, parameters);
      !reason.empty())
    return fail(kBadArguments, reason);
  // Catch output problems before spending time on the reconstruction.
  if (const int code = pcl_ms_tools::checkMeshOutput(options.output, error); code != kSuccess)
    return fail(code, error);
  if (const int code = pcl_ms_tools::checkMedialAxisOutput(options.medial_axis, error);
      code != kSuccess)
    return fail(code, error);

  const bool verbose = !options.quiet;
  pcl::PCLPointCloud2 cloud;
  double load_ms = 0;
  if (const int code =
          pcl_ms_tools::loadReconstructInput(options, parameters, cloud, load_ms, error);
      code != kSuccess)
    return fail(code, error);

  std::vector<pcl::Vertices> initial;
  if (!options.initial.empty())
    if (const int code = pcl_ms_tools::loadInitialTriangles(options, cloud, initial, error);
        code != kSuccess)
      return fail(code, error);

  if (verbose)
    pcl_ms_tools::printReconstructStart(options, parameters);
  pcl::console::TicToc timer;
  timer.tic();
  if (verbose) {
    std::fflush(stdout); // the progress line goes to stderr
    parameters.progress = pcl_ms_tools::ProgressLine();
  }
  std::vector<pcl::Vertices> polygons;
  pcl_ms::Result result;
  const bool reconstructed =
      parameters.use_normals
          ? reconstructAs<pcl::PointNormal>(cloud, parameters, initial, polygons, result, error)
          : reconstructAs<pcl::PointXYZ>(cloud, parameters, initial, polygons, result, error);
  const double reconstruct_ms = timer.toc();
  if (!reconstructed) {
    if (verbose)
      print_info("[failed]\n");
    return fail(kReconstructionFailure, error);
  }
  if (verbose) {
    print_info("[done, ");
    print_value("%.1f", reconstruct_ms);
    print_info(" ms : ");
    print_value("%zu", polygons.size());
    print_info(" triangles]\n");
  }

  double save_ms = 0;
  if (const int code = pcl_ms_tools::saveReconstructedMesh(options, std::move(cloud),
                                                           std::move(polygons), save_ms, error);
      code != kSuccess)
    return fail(code, error);
  if (const int code = pcl_ms_tools::saveReconstructedMedialAxis(options, result, error);
      code != kSuccess)
    return fail(code, error);
  if (verbose)
    pcl_ms_tools::printReconstructReport(result, load_ms, save_ms, result.triangles.size());
  return kSuccess;
}

} // namespace

int main(int argc, char **argv) {
  pcl_ms_tools::restartWithHugePageHeap(argv, pcl_ms_tools::HugePageHeap::kOnRequest);
  return pcl_ms_tools::runGuarded(run, argc, argv, pcl_ms_tools::kReconstructionFailure);
}
