// SPDX-License-Identifier: GPL-3.0-or-later
// pcl_ms_reconstruct_mpi: pcl_ms_reconstruct across the ranks of an MPI job,
// with the same options and the same triangles for any number of ranks.
//
// Rank 0 reads the cloud and broadcasts its points (the other ranks need no
// access to the file). Every rank prepares the points and builds the bucket
// tree the same way; each meshes its own buckets and seam zones, and the
// triangles a zone needs go to the rank that owns it (pcl_ms::BucketExchange;
// docs/algorithm.md, "Across processes"). Rank 0 ends with the whole
// surface, finishes it (hole filling, orientation) and writes the mesh.
//
// Failures: what every rank would see the same way (arguments, the file) is
// agreed on and every rank exits with the same code; a failure on one rank
// alone (a unit's exception, the time limit) prints its line and aborts the
// job, so no rank waits for it.
#include "mpi_bucket_exchange.h"
#include "reconstruct_cli.h"
#include "tool_support.h"

#include <pcl_ms/reconstruct.h>

#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include <sys/resource.h>

namespace {

using pcl::console::print_info;
using pcl::console::print_value;
using pcl_ms_tools::fail;
using pcl_ms_tools::kBadArguments;
using pcl_ms_tools::kReconstructionFailure;
using pcl_ms_tools::kSuccess;
using pcl_ms_tools::SilencePclMessages;

struct Job {
  MPI_Comm communicator = MPI_COMM_WORLD;
  int rank = 0, ranks = 1;
};

/// Rank 0's status, on every rank.
int statusOfRankZero(const Job &job, int status) {
  MPI_Bcast(&status, 1, MPI_INT, 0, job.communicator);
  return status;
}

/// One rank's failure ends the job: the others may be waiting for it.
[[noreturn]] void abortJob(const Job &job, int code, const std::string &reason) {
  fail(code, job.ranks > 1 ? "rank " + std::to_string(job.rank) + ": " + reason : reason);
  MPI_Abort(job.communicator, code);
  std::exit(code); // MPI_Abort does not return; this satisfies [[noreturn]]
}

double peakResidentMegabytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0; // Linux: kilobytes
}

/// What each rank reports to rank 0 for the summary.
struct RankFigures {
  double peak_mb = 0, prepared_mb = 0, reconstruct_seconds = 0, sent_mb = 0, received_mb = 0;
};

void printRankTable(const std::vector<RankFigures> &figures) {
  print_info("\nRanks:\n");
  // "prepared": the peak once the points are prepared, before any bucket:
  // what every rank pays for holding the whole cloud.
  print_info("  %-6s %14s %14s %16s %14s %14s\n", "rank", "peak RSS (MB)", "prepared (MB)",
             "reconstruct (s)", "sent (MB)", "received (MB)");
  double total_peak = 0;
  for (std::size_t r = 0; r < figures.size(); ++r) {
    print_info("  %-6zu ", r);
    print_value("%14.1f %14.1f %16.2f %14.1f %14.1f\n", figures[r].peak_mb, figures[r].prepared_mb,
                figures[r].reconstruct_seconds, figures[r].sent_mb, figures[r].received_mb);
    total_peak += figures[r].peak_mb;
  }
  pcl_ms_tools::printRow("peak RSS, all ranks", "%10.1f", total_peak);
}

/// Broadcasts rank 0's points and meshes them on every rank; rank 0 gets
/// the triangles. The points are freed on return, before rank 0 builds the
/// output mesh.
template <typename PointT>
pcl_ms::Result meshAs(const Job &job, const pcl::PCLPointCloud2 &cloud,
                      const pcl_ms::Parameters &parameters,
                      pcl_ms_mpi::MpiBucketExchange &exchange) {
  pcl::PointCloud<PointT> points;
  if (job.rank == 0) {
    SilencePclMessages silence;
    pcl::fromPCLPointCloud2(cloud, points);
  }
  std::uint64_t count = points.size();
  MPI_Bcast(&count, 1, MPI_UINT64_T, 0, job.communicator);
  points.resize(count);
  pcl_ms_mpi::broadcastBytes(points.data(), count * sizeof(PointT), 0, job.communicator);

  // As pcl::MedialScaffoldReconstruction passes them: no indices, normals
  // from the point type.
  pcl_ms::PointView view;
  view.xyz = points.empty() ? nullptr : &points[0].x;
  view.size = points.size();
  view.stride = sizeof(PointT);
  if constexpr (pcl::traits::has_normal_v<PointT>) {
    if (parameters.use_normals) {
      view.normals = points.empty() ? nullptr : &points[0].normal_x;
      view.normal_stride = sizeof(PointT);
    }
  }
  try {
    return pcl_ms::reconstruct(view, parameters, exchange);
  } catch (const std::exception &error) {
    abortJob(job, kReconstructionFailure, std::string("reconstruction failed: ") + error.what());
  }
}

int run(const Job &job, int argc, char **argv) {
  const bool on_rank_zero = job.rank == 0;
  // Every rank parses the same arguments, so every rank reaches the same verdict.
  pcl_ms_tools::ReconstructOptions options;
  std::string error;
  if (!pcl_ms_tools::parseReconstructArguments(argc, argv, options, error))
    return on_rank_zero ? fail(kBadArguments, error) : kBadArguments;
  if (options.help) {
    if (on_rank_zero)
      pcl_ms_tools::printReconstructHelp(
          argv[0], "Meshes a point cloud across the ranks of an MPI job (mpirun -np N ...),\n"
                   "with the same triangles as pcl_ms_reconstruct given the same options.");
    return kSuccess;
  }
  if (!options.initial.empty()) {
    error = "-initial is not supported across processes: use pcl_ms_reconstruct";
    return on_rank_zero ? fail(kBadArguments, error) : kBadArguments;
  }
  pcl_ms::Parameters parameters;
  if (const std::string reason = pcl_ms_tools::reconstructParameters(options, parameters);
      !reason.empty())
    return on_rank_zero ? fail(kBadArguments, reason) : kBadArguments;

  const bool verbose = on_rank_zero && !options.quiet;
  pcl::PCLPointCloud2 cloud;
  double load_ms = 0;
  int status = kSuccess;
  if (on_rank_zero) {
    status = pcl_ms_tools::checkMeshOutput(options.output, error);
    if (status == kSuccess)
      status = pcl_ms_tools::checkMedialAxisOutput(options.medial_axis, error);
    if (status == kSuccess)
      status = pcl_ms_tools::loadReconstructInput(options, parameters, cloud, load_ms, error);
  }
  status = statusOfRankZero(job, status);
  if (status != kSuccess)
    return on_rank_zero ? fail(status, error) : status;

  // The viewpoint may come from the file, which only rank 0 read.
  double viewpoint[4] = {parameters.viewpoint ? 1.0 : 0.0, 0, 0, 0};
  if (parameters.viewpoint)
    std::copy(parameters.viewpoint->begin(), parameters.viewpoint->end(), viewpoint + 1);
  MPI_Bcast(viewpoint, 4, MPI_DOUBLE, 0, job.communicator);
  if (viewpoint[0] != 0)
    parameters.viewpoint = {{viewpoint[1], viewpoint[2], viewpoint[3]}};

  if (verbose) {
    pcl_ms_tools::printReconstructStart(options, parameters);
    print_info("on ");
    print_value("%d", job.ranks);
    print_info(" ranks ");
    std::fflush(stdout);                                // the progress lines go to stderr
    parameters.progress = pcl_ms_tools::ProgressLine(); // rank 0's own units
  }
  const auto start = std::chrono::steady_clock::now();
  const auto secondsSinceStart = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  pcl_ms_mpi::MpiBucketExchange exchange(job.communicator, [&](const std::string &stage) {
    if (verbose)
      std::fprintf(stderr, "  all ranks: %s done, %.1f s elapsed\n", stage.c_str(),
                   secondsSinceStart());
  });
  const pcl_ms::Result result = parameters.use_normals
                                    ? meshAs<pcl::PointNormal>(job, cloud, parameters, exchange)
                                    : meshAs<pcl::PointXYZ>(job, cloud, parameters, exchange);
  std::vector<pcl::Vertices> polygons(result.triangles.size());
  for (std::size_t t = 0; t < result.triangles.size(); ++t)
    polygons[t].vertices.assign(result.triangles[t].begin(), result.triangles[t].end());
  const double reconstruct_seconds = secondsSinceStart();
  if (verbose) {
    print_info("[done, ");
    print_value("%.1f", reconstruct_seconds * 1e3);
    print_info(" ms : ");
    print_value("%zu", polygons.size());
    print_info(" triangles]\n");
  }

  double save_ms = 0;
  if (on_rank_zero) {
    status = pcl_ms_tools::saveReconstructedMesh(options, std::move(cloud), std::move(polygons),
                                                 save_ms, error);
    if (status == kSuccess)
      status = pcl_ms_tools::saveReconstructedMedialAxis(options, result, error);
  }
  RankFigures mine{peakResidentMegabytes(), result.peak_memory.prepare / 1048576.0,
                   reconstruct_seconds, static_cast<double>(exchange.bytesSent()) / (1 << 20),
                   static_cast<double>(exchange.bytesReceived()) / (1 << 20)};
  std::vector<RankFigures> figures(on_rank_zero ? job.ranks : 0);
  MPI_Gather(&mine, sizeof(RankFigures), MPI_BYTE, figures.data(), sizeof(RankFigures), MPI_BYTE, 0,
             job.communicator);
  status = statusOfRankZero(job, status);
  if (status != kSuccess)
    return on_rank_zero ? fail(status, error) : status;
  if (verbose) {
    pcl_ms_tools::printReconstructReport(result, load_ms, save_ms);
    printRankTable(figures);
    // Where rank 0's memory goes beyond the others': it alone finishes.
    const pcl_ms::StagePeakMemory &peaks = result.peak_memory;
    pcl_ms_tools::printRow("rank 0 MB, meshed", "%10.1f", peaks.greedy / 1048576.0);
    pcl_ms_tools::printRow("rank 0 MB, finished", "%10.1f", peaks.finish / 1048576.0);
  }
  return kSuccess;
}

} // namespace

int main(int argc, char **argv) {
  // Only the main thread calls MPI; TBB's workers mesh units between calls.
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  Job job;
  MPI_Comm_rank(job.communicator, &job.rank);
  MPI_Comm_size(job.communicator, &job.ranks);
  int code = kSuccess;
  try {
    code = run(job, argc, argv);
  } catch (const std::exception &exception) {
    abortJob(job, kReconstructionFailure, std::string("unexpected failure: ") + exception.what());
  }
  MPI_Finalize();
  return code;
}
