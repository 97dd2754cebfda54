// SPDX-License-Identifier: GPL-3.0-or-later
// pcl_ms_reconstruct_mpi: pcl_ms_reconstruct across the ranks of an MPI job,
// with the same options and the same triangles for any number of ranks.
//
// The ranks read their own byte ranges of a binary PCD or PLY, prepare them
// together (pcl_ms::preparePointsTogether), mesh them by owner and finish
// the surface with the triangles in runs over the ranks
// (pcl_ms::reconstructSlices): no rank holds the cloud or the surface; into
// a PLY, rank 0 writes the runs as the ranks send them, a piece at a time
// (else it receives the finished triangles to write). A file rank 0 reads
// whole (other formats) is meshed by a unit farm: rank 0 prepares it,
// builds the bucket tree and hands each bucket and seam zone as a task to
// a free rank (pcl_ms_mpi::MpiUnitFarm), meshing one itself meanwhile; the
// other ranks hold one unit at a time, and rank 0 finishes the surface
// (hole filling, orientation) (docs/algorithm.md, "Across processes").
// Rank 0 writes the mesh. With -initial, or on one rank, rank 0 meshes the
// cloud alone, as pcl_ms_reconstruct does.
//
// Failures: what every rank would see the same way (arguments, the file) is
// agreed on and every rank exits with the same code; a failure on one rank
// alone (a unit's exception, the time limit) prints its line and aborts the
// job, so no rank waits for it.
#include "huge_page_heap.h"
#include "mpi_bucket_exchange.h"
#include "mpi_cloud_reader.h"
#include "mpi_process_group.h"
#include "reconstruct_cli.h"
#include "tool_support.h"

#include <pcl_ms/deadline.h>
#include <pcl_ms/io.h>
#include <pcl_ms/medial_scaffold_reconstruction.h>
#include <pcl_ms/prepared_points.h>
#include <pcl_ms/reconstruct.h>

#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <mpi.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <sys/resource.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

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
  double peak_mb = 0, read_mb = 0, prepared_mb = 0, reconstruct_seconds = 0, sent_mb = 0,
         received_mb = 0;
};

void printRankTable(const std::vector<RankFigures> &figures) {
  print_info("\nRanks:\n");
  // "read": the peak once the points are in (rank 0: all of them, the
  // others: their part until sent); "prepared": rank 0's once they are
  // prepared, before any bucket; "reconstruct": the others' time meshing.
  print_info("  %-6s %14s %10s %14s %16s %10s %14s\n", "rank", "peak RSS (MB)", "read (MB)",
             "prepared (MB)", "reconstruct (s)", "sent (MB)", "received (MB)");
  double total_peak = 0;
  for (std::size_t r = 0; r < figures.size(); ++r) {
    print_info("  %-6zu ", r);
    print_value("%14.1f %10.1f %14.1f %16.2f %10.1f %14.1f\n", figures[r].peak_mb,
                figures[r].read_mb, figures[r].prepared_mb, figures[r].reconstruct_seconds,
                figures[r].sent_mb, figures[r].received_mb);
    total_peak += figures[r].peak_mb;
  }
  pcl_ms_tools::printRow("peak RSS, all ranks", "%10.1f", total_peak);
}

/// What a rank found reading its byte range.
struct SliceStatus {
  int code = kSuccess;
  int all_finite = 1; // every point has finite x, y, z
  int readers = 1;    // ranks that read a part
};

/// This rank's records of a file read in parts: the cloud's records
/// [first_record, first_record + points.size()).
template <typename PointT> struct CloudPart {
  pcl::PointCloud<PointT> points;
  std::uint64_t first_record = 0;
};

/// Every rank reads the records of its own byte range of a binary PCD or PLY
/// (docs/algorithm.md, "Across processes"). A range the file does not hold
/// fails on its rank, with the reason there, and every rank returns
/// kIoFailure.
template <typename PointT>
SliceStatus readOwnPart(const Job &job, const std::string &path,
                        const pcl_ms_mpi::BinaryCloudLayout &layout, CloudPart<PointT> &part) {
  // Without a shared filesystem the other ranks may not see the file (or
  // see another): then rank 0 reads it all.
  std::error_code code;
  int sees = std::filesystem::file_size(path, code) == layout.file_size && !code;
  int all_see = 0;
  MPI_Allreduce(&sees, &all_see, 1, MPI_INT, MPI_MIN, job.communicator);
  const int readers = all_see ? job.ranks : 1;
  const std::uint64_t begin =
      pcl_ms_mpi::firstRecordOf(std::min(job.rank, readers), readers, layout.points);
  const std::uint64_t end =
      pcl_ms_mpi::firstRecordOf(std::min(job.rank + 1, readers), readers, layout.points);
  SliceStatus mine;
  mine.readers = readers;
  std::vector<unsigned char> bytes;
  std::string error;
  if (!pcl_ms_mpi::readRecords(path, layout, begin, end, bytes, error)) {
    fail(pcl_ms_tools::kIoFailure,
         job.ranks > 1 ? "rank " + std::to_string(job.rank) + ": " + error : error);
    mine.code = pcl_ms_tools::kIoFailure;
  }
  SliceStatus all;
  all.readers = readers;
  MPI_Allreduce(&mine.code, &all.code, 1, MPI_INT, MPI_MAX, job.communicator);
  if (all.code != kSuccess)
    return all;
  part.first_record = begin;
  part.points.resize(end - begin);
  auto field = [&](std::size_t record, std::uint32_t offset) {
    float value;
    std::memcpy(&value, bytes.data() + record * layout.record_bytes + offset, sizeof value);
    return value;
  };
  for (std::size_t i = 0; i < part.points.size(); ++i) {
    PointT &point = part.points[i];
    point.x = field(i, layout.xyz[0]);
    point.y = field(i, layout.xyz[1]);
    point.z = field(i, layout.xyz[2]);
    mine.all_finite &= std::isfinite(point.x) && std::isfinite(point.y) && std::isfinite(point.z);
    if constexpr (pcl::traits::has_normal_v<PointT>)
      if (layout.hasNormals()) {
        point.normal_x = field(i, static_cast<std::uint32_t>(layout.normal[0]));
        point.normal_y = field(i, static_cast<std::uint32_t>(layout.normal[1]));
        point.normal_z = field(i, static_cast<std::uint32_t>(layout.normal[2]));
      }
  }
  MPI_Allreduce(&mine.all_finite, &all.all_finite, 1, MPI_INT, MPI_MIN, job.communicator);
  return all;
}

/// Rank 0 gets every rank's part, in record order (the others' go).
template <typename PointT>
pcl::PointCloud<PointT> joinPartsOnRankZero(const Job &job, CloudPart<PointT> &&part,
                                            std::uint64_t records) {
  std::vector<std::uint64_t> firsts(static_cast<std::size_t>(job.ranks), 0);
  MPI_Gather(&part.first_record, 1, MPI_UINT64_T, firsts.data(), 1, MPI_UINT64_T, 0,
             job.communicator);
  pcl::PointCloud<PointT> all;
  if (job.rank == 0) {
    all.resize(records);
    std::copy(part.points.begin(), part.points.end(), all.begin());
    for (int r = 1; r < job.ranks; ++r) {
      const std::uint64_t first = firsts[static_cast<std::size_t>(r)];
      const std::uint64_t end =
          r + 1 < job.ranks ? firsts[static_cast<std::size_t>(r + 1)] : records;
      pcl_ms_mpi::receiveBytes(all.data() + first, (std::max(end, first) - first) * sizeof(PointT),
                               r, job.communicator);
    }
  } else {
    pcl_ms_mpi::sendBytes(part.points.data(), part.points.size() * sizeof(PointT), 0,
                          job.communicator);
  }
  pcl::PointCloud<PointT>().swap(part.points);
  return all;
}

/// Hands the heap's free pages back to the system. Rank 0 meshes units on a
/// thread of its own, whose small allocations leave free pages scattered
/// through its heap; returned after each stage, they no longer count in the
/// finishing stage's peak (docs/algorithm.md, "Across processes").
void returnFreeMemory() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

/// Rank 0 with initial triangles: they are honoured by the one-piece path
/// only, so rank 0 meshes the cloud alone, as pcl_ms_reconstruct does,
/// through the same PCL class.
template <typename PointT>
pcl_ms::Result meshWithInitialTriangles(const Job &job, pcl::PointCloud<PointT> &&points,
                                        const pcl_ms::Parameters &parameters,
                                        const std::vector<pcl::Vertices> &initial) {
  pcl::MedialScaffoldReconstruction<PointT> reconstruction;
  reconstruction.setInputCloud(pcl::make_shared<pcl::PointCloud<PointT>>(std::move(points)));
  reconstruction.setParameters(parameters);
  reconstruction.setInitialTriangles(initial);
  reconstruction.setUseSensorOrigin(false); // run() decided the viewpoint
  pcl::PointCloud<PointT> input_copy;       // this overload of PCL's interface hands the input back
  std::vector<pcl::Vertices> polygons;
  {
    SilencePclMessages silence;
    reconstruction.reconstruct(input_copy, polygons);
  }
  if (!reconstruction.getErrorMessage().empty())
    abortJob(job, kReconstructionFailure,
             "reconstruction failed: " + reconstruction.getErrorMessage());
  return reconstruction.getResult();
}

/// The points of `cloud` as pcl::MedialScaffoldReconstruction passes them:
/// no indices, normals from the point type.
template <typename PointT>
pcl_ms::PointView viewOfCloud(const pcl::PointCloud<PointT> &cloud, bool use_normals) {
  pcl_ms::PointView view;
  view.xyz = cloud.empty() ? nullptr : &cloud[0].x;
  view.size = cloud.size();
  view.stride = sizeof(PointT);
  if constexpr (pcl::traits::has_normal_v<PointT>) {
    if (use_normals) {
      view.normals = cloud.empty() ? nullptr : &cloud[0].normal_x;
      view.normal_stride = sizeof(PointT);
    }
  }
  return view;
}

/// Rank 0: meshes `points`, with the other ranks meshing the units it
/// hands out, and frees them as soon as the core has prepared its copy.
template <typename PointT>
pcl_ms::Result meshPoints(const Job &job, pcl::PointCloud<PointT> &&points,
                          const pcl_ms::Parameters &parameters, pcl_ms_mpi::MpiUnitFarm &exchange) {
  pcl::PointCloud<PointT> owned = std::move(points);
  exchange.onPointsPrepared([&owned] {
    pcl::PointCloud<PointT>().swap(owned);
    returnFreeMemory();
  });
  try {
    pcl_ms::Result result =
        pcl_ms::reconstruct(viewOfCloud(owned, parameters.use_normals), parameters, exchange);
    exchange.onPointsPrepared({});
    return result;
  } catch (const std::exception &error) {
    abortJob(job, kReconstructionFailure, std::string("reconstruction failed: ") + error.what());
  }
}

/// Every rank meshes the prepared slices with the others
/// (pcl_ms::reconstructSlices: buckets by owner); rank 0 gets the result,
/// and, given `runs`, every rank its run of a bucketed surface.
/// An unusable cloud fails alike on every rank, or on rank 0 alone where it
/// alone works (one piece, the finishing): the status says so, `error`
/// why. A failure on one rank while the others wait (the time limit, an
/// unexpected error) aborts the job.
int meshSlices(const Job &job, pcl_ms::PreparedSlice &&slice, const pcl_ms::Parameters &parameters,
               pcl_ms_mpi::MpiProcessGroup &group, pcl_ms::FinishedRun *runs,
               pcl_ms::Result &result, std::string &error) {
  try {
    result = pcl_ms::reconstructSlices(std::move(slice), parameters, group, runs);
    return kSuccess;
  } catch (const pcl_ms::TimeLimitExceeded &late) {
    abortJob(job, kReconstructionFailure, std::string("reconstruction failed: ") + late.what());
  } catch (const pcl_ms::ReconstructionError &unusable) {
    error = std::string("reconstruction failed: ") + unusable.what();
    return kReconstructionFailure;
  } catch (const std::exception &unexpected) {
    abortJob(job, kReconstructionFailure,
             std::string("reconstruction failed: ") + unexpected.what());
  }
}

/// Every rank prepares its part together with the others (NaN, duplicates,
/// far points, the order: docs/algorithm.md, "Across processes"), so that
/// no rank holds the cloud's records; the part is freed. An unusable cloud
/// (too few points, ...) fails alike on every rank: the status is returned
/// everywhere, with the reason printed by rank 0.
template <typename PointT>
int prepareParts(const Job &job, CloudPart<PointT> &&part, const pcl_ms::Parameters &parameters,
                 pcl_ms::PreparedSlice &slice) {
  pcl_ms_mpi::MpiProcessGroup group(job.communicator);
  std::string error;
  try {
    tbb::task_arena arena(std::max(1, parameters.num_threads));
    arena.execute([&] {
      slice = pcl_ms::preparePointsTogether(viewOfCloud(part.points, parameters.use_normals),
                                            part.first_record, parameters.use_normals, group);
    });
  } catch (const pcl_ms::ReconstructionError &unusable) {
    error = unusable.what();
  } catch (const std::exception &unexpected) {
    abortJob(job, kReconstructionFailure,
             std::string("reconstruction failed: ") + unexpected.what());
  }
  pcl::PointCloud<PointT>().swap(part.points);
  returnFreeMemory();
  if (error.empty())
    return kSuccess;
  return job.rank == 0 ? fail(kReconstructionFailure, "reconstruction failed: " + error)
                       : kReconstructionFailure;
}

/// Rank 0 writes the surface left in runs (writePlyFromInput's bytes): the
/// others send theirs a piece at a time, in rank order, so that no rank
/// holds more than its run and a piece. Rank 0 takes every piece even after
/// a failure, so that no rank waits. Collective; rank 0's status.
int writeRunsAsPly(const Job &job, const std::string &output, const std::string &input,
                   const pcl_ms_mpi::BinaryCloudLayout &layout, const pcl_ms::FinishedRun &run,
                   std::string &error) {
  constexpr std::size_t piece = std::size_t(1) << 20; // triangles (12 MB)
  std::uint64_t mine = run.triangles.size();
  std::vector<std::uint64_t> counts(static_cast<std::size_t>(job.ranks), 0);
  MPI_Gather(&mine, 1, MPI_UINT64_T, counts.data(), 1, MPI_UINT64_T, 0, job.communicator);
  if (job.rank != 0) {
    for (std::size_t begin = 0; begin < run.triangles.size(); begin += piece)
      pcl_ms_mpi::sendBytes(run.triangles.data() + begin,
                            std::min(piece, run.triangles.size() - begin) *
                                sizeof(pcl_ms::Triangle),
                            0, job.communicator);
    return kSuccess;
  }
  pcl_ms_mpi::PlyFromInputWriter writer;
  writer.open(output, input, layout, run.total);
  writer.add(run.triangles.data(), run.triangles.size());
  std::vector<pcl_ms::Triangle> arrived;
  for (int r = 1; r < job.ranks; ++r)
    for (std::uint64_t left = counts[static_cast<std::size_t>(r)]; left > 0;) {
      arrived.resize(static_cast<std::size_t>(std::min<std::uint64_t>(piece, left)));
      pcl_ms_mpi::receiveBytes(arrived.data(), arrived.size() * sizeof(pcl_ms::Triangle), r,
                               job.communicator);
      writer.add(arrived.data(), arrived.size());
      left -= arrived.size();
    }
  return writer.close(error) ? kSuccess : pcl_ms_tools::kIoFailure;
}

/// How the input reaches the ranks; rank 0 decides, every rank gets it.
struct Input {
  pcl_ms_mpi::BinaryCloudLayout layout;
  int in_parts = 0; // each rank reads its own byte range of a binary PCD or PLY
};

/// The points on every rank, meshed; rank 0 saves the mesh. `cloud` is
/// rank 0's loaded file when the ranks do not read it in parts.
template <typename PointT>
int loadMeshAndSave(const Job &job, const pcl_ms_tools::ReconstructOptions &options,
                    pcl_ms::Parameters parameters, const Input &input, pcl::PCLPointCloud2 &cloud,
                    const std::vector<pcl::Vertices> &initial, const std::string &fields,
                    double load_ms) {
  const bool on_rank_zero = job.rank == 0;
  const bool verbose = on_rank_zero && !options.quiet;
  pcl::PointCloud<PointT> points; // rank 0's whole cloud, unless the ranks prepare parts
  // Read in parts by several ranks (without initial triangles, which need
  // the whole cloud on rank 0): each rank's slice of the points, prepared
  // together.
  std::optional<pcl_ms::PreparedSlice> slice;
  double prepare_seconds = 0;
  SliceStatus read;
  if (input.in_parts) {
    if (verbose) {
      pcl::console::print_highlight("Reading ");
      print_value("%s ", options.input.c_str());
    }
    const auto read_start = std::chrono::steady_clock::now();
    CloudPart<PointT> part;
    read = readOwnPart(job, options.input, input.layout, part);
    if (read.code != kSuccess) {
      if (verbose)
        print_info("[failed]\n");
      return read.code;
    }
    load_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - read_start)
            .count();
    if (verbose) {
      print_info("[done, ");
      print_value("%.1f", load_ms);
      print_info(" ms : ");
      print_value("%zu", static_cast<std::size_t>(input.layout.points));
      print_info(" points, ");
      print_value("%d", read.readers);
      print_info(read.readers == 1 ? " part]\n" : " parts]\n");
      print_info("Available dimensions: ");
      print_value("%s\n", fields.c_str());
    }
    // One rank alone meshes as one process does: sharing would only copy.
    if (initial.empty() && job.ranks > 1) {
      const auto prepare_start = std::chrono::steady_clock::now();
      slice.emplace();
      const int prepared = prepareParts(job, std::move(part), parameters, *slice);
      if (prepared != kSuccess)
        return prepared;
      prepare_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - prepare_start).count();
    } else {
      points = joinPartsOnRankZero(job, std::move(part), input.layout.points);
    }
  } else if (on_rank_zero) {
    SilencePclMessages silence;
    pcl::fromPCLPointCloud2(cloud, points);
  }
  const double read_mb = peakResidentMegabytes();

  if (!on_rank_zero && !slice) {
    // The other ranks mesh the units rank 0 sends them, one at a time.
    pcl_ms_mpi::ServedUnits served;
    try {
      served = pcl_ms_mpi::serveUnits(job.communicator, parameters);
    } catch (const std::exception &error) {
      abortJob(job, kReconstructionFailure, std::string("reconstruction failed: ") + error.what());
    }
    RankFigures mine{peakResidentMegabytes(),
                     read_mb,
                     0,
                     served.seconds,
                     static_cast<double>(served.bytes_sent) / (1 << 20),
                     static_cast<double>(served.bytes_received) / (1 << 20)};
    MPI_Gather(&mine, sizeof(RankFigures), MPI_BYTE, nullptr, 0, MPI_BYTE, 0, job.communicator);
    return statusOfRankZero(job, kSuccess);
  }

  if (verbose) {
    pcl_ms_tools::printReconstructStart(options, parameters);
    print_info("on ");
    print_value("%d", job.ranks);
    print_info(" ranks ");
    std::fflush(stdout);                                // the progress lines go to stderr
    parameters.progress = pcl_ms_tools::ProgressLine(); // rank 0's own units
  }
  // A binary PCD or PLY of x y z only, all finite, into a PLY: the vertices
  // go from the input to the output a block at a time, so rank 0 never
  // holds the cloud (the same bytes as PCL's writer); a bucketed surface
  // stays in runs on the ranks until it is written.
  const bool streamed = input.in_parts && input.layout.xyz_only && read.all_finite &&
                        input.layout.height == 1 && pcl_ms::fileExtension(options.output) == ".ply";
  pcl_ms::FinishedRun run;
  const auto start = std::chrono::steady_clock::now();
  const auto secondsSinceStart = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  pcl_ms::Result result;
  std::size_t bytes_sent = 0, bytes_received = 0;
  int status = kSuccess;
  std::string error;
  if (slice) {
    // Every rank meshes the buckets and zones it owns (buckets by owner).
    pcl_ms_mpi::MpiProcessGroup group(job.communicator);
    status = meshSlices(job, std::move(*slice), parameters, group, streamed ? &run : nullptr,
                        result, error);
    slice.reset();
    result.timings.prepare = prepare_seconds;
    result.timings.total += prepare_seconds;
    bytes_sent = group.bytesSent();
    bytes_received = group.bytesReceived();
  } else {
    pcl_ms_mpi::MpiUnitFarm exchange(job.communicator, parameters, [&](const std::string &stage) {
      returnFreeMemory();
      if (verbose)
        std::fprintf(stderr, "  all ranks: %s done, %.1f s elapsed\n", stage.c_str(),
                     secondsSinceStart());
    });
    result = initial.empty()
                 ? meshPoints(job, std::move(points), parameters, exchange)
                 : meshWithInitialTriangles(job, std::move(points), parameters, initial);
    exchange.release(); // the other ranks are done
    bytes_sent = exchange.bytesSent();
    bytes_received = exchange.bytesReceived();
  }
  const double reconstruct_seconds = secondsSinceStart();
  const std::size_t triangle_count =
      run.used ? static_cast<std::size_t>(run.total) : result.triangles.size();
  if (verbose && status == kSuccess) {
    print_info("[done, ");
    print_value("%.1f", reconstruct_seconds * 1e3);
    print_info(" ms : ");
    print_value("%zu", triangle_count);
    print_info(" triangles]\n");
  } else if (verbose) {
    print_info("[failed]\n");
  }

  // Rank 0 writes: streamed (see above; with the ranks sending their runs),
  // or else it loads the file now, after the meshing has freed the points.
  double save_ms = 0;
  const auto saveStreamed = [&](const std::function<int()> &write) {
    if (verbose) {
      pcl::console::print_highlight("Saving ");
      print_value("%s ", options.output.c_str());
    }
    const auto save_start = std::chrono::steady_clock::now();
    status = write();
    save_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - save_start)
            .count();
    if (verbose) {
      if (status == kSuccess) {
        print_info("[done, ");
        print_value("%.1f", save_ms);
        print_info(" ms]\n");
      } else {
        print_info("[failed]\n");
      }
    }
  };
  if (run.used) {
    int all_meshed = status == kSuccess;
    MPI_Allreduce(MPI_IN_PLACE, &all_meshed, 1, MPI_INT, MPI_MIN, job.communicator);
    if (all_meshed)
      saveStreamed([&] {
        return writeRunsAsPly(job, options.output, options.input, input.layout, run, error);
      });
    else if (status == kSuccess)
      status = kReconstructionFailure; // another rank's failure, which it printed
    run = pcl_ms::FinishedRun();
  } else if (on_rank_zero && status == kSuccess) {
    if (streamed) {
      saveStreamed([&] {
        return pcl_ms_mpi::writePlyFromInput(options.output, options.input, input.layout,
                                             result.triangles, error)
                   ? kSuccess
                   : pcl_ms_tools::kIoFailure;
      });
    } else {
      if (input.in_parts) {
        SilencePclMessages silence;
        Eigen::Vector4f origin;
        if (!pcl_ms::loadPointCloud(options.input, cloud, error, &origin)) {
          error = options.input + ": " + error;
          status = pcl_ms_tools::kIoFailure;
        }
      }
      if (status == kSuccess) {
        std::vector<pcl::Vertices> polygons(result.triangles.size());
        for (std::size_t t = 0; t < result.triangles.size(); ++t)
          polygons[t].vertices.assign(result.triangles[t].begin(), result.triangles[t].end());
        status = pcl_ms_tools::saveReconstructedMesh(options, std::move(cloud), std::move(polygons),
                                                     save_ms, error);
      }
    }
  }
  if (on_rank_zero && status == kSuccess)
    status = pcl_ms_tools::saveReconstructedMedialAxis(options, result, error);
  RankFigures mine{peakResidentMegabytes(),
                   read_mb,
                   result.peak_memory.prepare / 1048576.0,
                   reconstruct_seconds,
                   static_cast<double>(bytes_sent) / (1 << 20),
                   static_cast<double>(bytes_received) / (1 << 20)};
  std::vector<RankFigures> figures(on_rank_zero ? job.ranks : 0);
  MPI_Gather(&mine, sizeof(RankFigures), MPI_BYTE, figures.data(), sizeof(RankFigures), MPI_BYTE, 0,
             job.communicator);
  status = statusOfRankZero(job, status);
  if (status != kSuccess)
    return on_rank_zero ? fail(status, error) : status;
  if (verbose) {
    pcl_ms_tools::printReconstructReport(result, load_ms, save_ms, triangle_count);
    printRankTable(figures);
    // Rank 0's peaks (the unit farm: where it goes beyond the others', as it alone finishes).
    const pcl_ms::StagePeakMemory &peaks = result.peak_memory;
    pcl_ms_tools::printRow("rank 0 MB, meshed", "%10.1f", peaks.greedy / 1048576.0);
    pcl_ms_tools::printRow("rank 0 MB, finished", "%10.1f", peaks.finish / 1048576.0);
  }
  return kSuccess;
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
  pcl_ms::Parameters parameters;
  if (const std::string reason = pcl_ms_tools::reconstructParameters(options, parameters);
      !reason.empty())
    return on_rank_zero ? fail(kBadArguments, reason) : kBadArguments;

  pcl::PCLPointCloud2 cloud;
  std::vector<pcl::Vertices> initial; // rank 0's, from -initial
  Input input;
  std::string fields;
  double load_ms = 0;
  int status = kSuccess;
  if (on_rank_zero) {
    status = pcl_ms_tools::checkMeshOutput(options.output, error);
    if (status == kSuccess)
      status = pcl_ms_tools::checkMedialAxisOutput(options.medial_axis, error);
    // A binary PCD or PLY is read in parts, unless normals are to be estimated
    // (on the whole cloud) or asked for and absent (the loader says so), or
    // initial triangles are given (rank 0 meshes them in one piece).
    if (status == kSuccess && options.estimate_normals == 0 && options.initial.empty() &&
        pcl_ms_mpi::describeBinaryCloud(options.input, input.layout, fields) &&
        (!options.normals || input.layout.hasNormals())) {
      input.in_parts = 1;
      if (!parameters.viewpoint && !options.no_viewpoint) {
        pcl::PCLPointCloud2 header;
        header.width = input.layout.width;
        header.height = input.layout.height;
        const Eigen::Vector4f origin(input.layout.origin[0], input.layout.origin[1],
                                     input.layout.origin[2], 0);
        parameters.viewpoint = pcl_ms_tools::sensorViewpoint(header, origin);
      }
    } else if (status == kSuccess) {
      status = pcl_ms_tools::loadReconstructInput(options, parameters, cloud, load_ms, error);
      if (status == kSuccess && !options.initial.empty())
        status = pcl_ms_tools::loadInitialTriangles(options, cloud, initial, error);
    }
  }
  status = statusOfRankZero(job, status);
  if (status != kSuccess)
    return on_rank_zero ? fail(status, error) : status;
  MPI_Bcast(&input, sizeof input, MPI_BYTE, 0, job.communicator);

  // The viewpoint may come from the file's header, which only rank 0 read.
  double viewpoint[4] = {parameters.viewpoint ? 1.0 : 0.0, 0, 0, 0};
  if (parameters.viewpoint)
    std::copy(parameters.viewpoint->begin(), parameters.viewpoint->end(), viewpoint + 1);
  MPI_Bcast(viewpoint, 4, MPI_DOUBLE, 0, job.communicator);
  if (viewpoint[0] != 0)
    parameters.viewpoint = {{viewpoint[1], viewpoint[2], viewpoint[3]}};

  return parameters.use_normals ? loadMeshAndSave<pcl::PointNormal>(job, options, parameters, input,
                                                                    cloud, initial, fields, load_ms)
                                : loadMeshAndSave<pcl::PointXYZ>(job, options, parameters, input,
                                                                 cloud, initial, fields, load_ms);
}

} // namespace

int main(int argc, char **argv) {
  pcl_ms_tools::restartWithHugePageHeap(argv, pcl_ms_tools::HugePageHeap::kByDefault);
#ifdef __GLIBC__
  // Blocks of 1 MB and more (unit messages, per-bucket triangles) are
  // mapped and returned on free. Left to glibc's adaptive threshold they
  // came from the heap, and the gaps they left raised rank 0's peak in the
  // final stage (docs/algorithm.md, "Across processes").
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
#endif
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
