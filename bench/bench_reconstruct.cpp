// SPDX-License-Identifier: GPL-3.0-or-later
// bench_reconstruct: times pcl_ms::reconstruct against CGAL's advancing-front
// surface reconstruction (AFSR) and a bare 3-D Delaunay triangulation on the
// bunny vertices, on uniform samplings of the bunny reference surface and on
// any other clouds given. Every method runs in its own forked child so that
// its peak resident memory (VmHWM) is not mixed with the others'; pcl_ms and
// the Delaunay triangulation on one thread and, if asked, on more.
#include "child_process.h"
#include "mesh_report.h"
#include "surface_sampling.h"

#include <pcl_ms/io.h>
#include <pcl_ms/reconstruct.h>

#include <CGAL/Advancing_front_surface_reconstruction.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Spatial_lock_grid_3.h>

#include <tbb/task_arena.h>

#include <pcl/console/parse.h>
#include <pcl/console/print.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalPoint = Kernel::Point_3;

/// What a child reports back through its pipe (plain bytes, fixed size).
struct Measurement {
  bool ok = false;
  double seconds = 0;     // wall clock
  double cpu_seconds = 0; // CPU time of the child: robust when the machine is busy
  std::uint64_t triangles = 0;
  pcl_ms::StageTimings stages;          // pcl_ms only
  pcl_ms::StagePeakMemory stage_memory; // pcl_ms only
  char message[240] = {};
};

/// A finished run as the parent sees it.
struct Run {
  std::string method;
  Measurement measurement;
  double peak_mb = 0;
};

struct Input {
  std::string name;
  std::vector<float> xyz; // x, y, z per point
  std::size_t size() const { return xyz.size() / 3; }
};

double processCpuSeconds() {
  timespec time{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &time);
  return static_cast<double>(time.tv_sec) + 1e-9 * static_cast<double>(time.tv_nsec);
}

/// Wall and CPU time of the measured call only (not of input conversion).
class Stopwatch {
public:
  void stop(Measurement &measurement) const {
    measurement.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
    measurement.cpu_seconds = processCpuSeconds() - cpu_start_;
  }

private:
  std::chrono::steady_clock::time_point wall_start_ = std::chrono::steady_clock::now();
  double cpu_start_ = processCpuSeconds();
};

std::vector<CgalPoint> toCgalPoints(const Input &input) {
  std::vector<CgalPoint> points;
  points.reserve(input.size());
  for (std::size_t i = 0; i < input.size(); ++i)
    points.emplace_back(input.xyz[3 * i], input.xyz[3 * i + 1], input.xyz[3 * i + 2]);
  return points;
}

// --- The measured methods. Each runs inside the child process. -------------

Measurement runNothing(const Input &) {
  Measurement measurement;
  measurement.ok = true;
  return measurement;
}

Measurement runPclMs(const Input &input, int threads, bool one_piece) {
  pcl_ms::PointView view;
  view.xyz = input.xyz.data();
  view.size = input.size();
  pcl_ms::Parameters parameters;
  parameters.num_threads = threads;
  if (one_piece)
    parameters.bucket_points = input.size();
  const Stopwatch stopwatch;
  const pcl_ms::Result result = pcl_ms::reconstruct(view, parameters);
  Measurement measurement;
  stopwatch.stop(measurement);
  measurement.triangles = result.triangles.size();
  measurement.stages = result.timings;
  measurement.stage_memory = result.peak_memory;
  measurement.ok = true;
  return measurement;
}

Measurement runAfsr(const Input &input) {
  // Point conversion is input preparation, not part of the timed work.
  const std::vector<CgalPoint> points = toCgalPoints(input);
  std::vector<std::array<std::size_t, 3>> facets;
  const Stopwatch stopwatch;
  CGAL::advancing_front_surface_reconstruction(points.begin(), points.end(),
                                               std::back_inserter(facets));
  Measurement measurement;
  stopwatch.stop(measurement);
  measurement.triangles = facets.size();
  measurement.ok = true;
  return measurement;
}

Measurement runDelaunay(const Input &input) {
  const std::vector<CgalPoint> points = toCgalPoints(input);
  const Stopwatch stopwatch;
  CGAL::Delaunay_triangulation_3<Kernel> triangulation(points.begin(), points.end());
  Measurement measurement;
  stopwatch.stop(measurement);
  measurement.triangles = triangulation.number_of_finite_facets();
  measurement.ok = true;
  return measurement;
}

/// CGAL's non-blocking lock grid: a thread that meets a locked cell gives its
/// point back and retries it later. The default (priority blocking) waits,
/// and on a busy machine the lock holder is often descheduled.
using LockGrid = CGAL::Spatial_lock_grid_3<CGAL::Tag_non_blocking>;
/// Cells per axis of the lock grid: the value of CGAL's example.
constexpr int lock_grid_cells_per_axis = 50;

/// The bare triangulation on several threads, as CGAL's documentation sets
/// it up: concurrent containers, a lock grid over the bounding box, range
/// insertion inside an arena of `threads` threads.
Measurement runParallelDelaunay(const Input &input, int threads) {
  using DataStructure =
      CGAL::Triangulation_data_structure_3<CGAL::Triangulation_vertex_base_3<Kernel>,
                                           CGAL::Delaunay_triangulation_cell_base_3<Kernel>,
                                           CGAL::Parallel_tag>;
  using Triangulation =
      CGAL::Delaunay_triangulation_3<Kernel, DataStructure, CGAL::Default, LockGrid>;
  const std::vector<CgalPoint> points = toCgalPoints(input);
  CGAL::Bbox_3 box;
  for (const CgalPoint &point : points)
    box += point.bbox();
  Measurement measurement;
  tbb::task_arena arena(threads);
  const Stopwatch stopwatch;
  Triangulation::Lock_data_structure lock(box, lock_grid_cells_per_axis);
  arena.execute([&] {
    Triangulation triangulation(points.begin(), points.end(), &lock);
    stopwatch.stop(measurement);
    measurement.triangles = triangulation.number_of_finite_facets();
  });
  measurement.ok = true;
  return measurement;
}

/// Runs `method` in a forked child and collects its result and peak memory.
/// With calls > 1 the child calls it that many times and reports its fastest
/// call: a program meshing clusters in a loop pays the first call's costs
/// (a new heap's page faults, cold caches, libraries started) once.
Run runInChild(const std::string &name, const std::function<Measurement(const Input &)> &method,
               const Input &input, int calls = 1) {
  Run run;
  run.method = name;
  const pcl_ms_tools::ChildOutcome outcome = pcl_ms_tools::runInChild([&] {
    Measurement measurement = method(input);
    for (int call = 1; call < calls && measurement.ok; ++call) {
      const Measurement again = method(input);
      if (!again.ok || again.seconds < measurement.seconds)
        measurement = again;
    }
    return std::string(reinterpret_cast<const char *>(&measurement), sizeof(measurement));
  });
  run.peak_mb = outcome.peak_mb;
  if (outcome.ok && outcome.payload.size() == sizeof(Measurement))
    std::memcpy(&run.measurement, outcome.payload.data(), sizeof(Measurement));
  else
    std::snprintf(run.measurement.message, sizeof(run.measurement.message), "%s",
                  outcome.ok ? "malformed result" : outcome.error.c_str());
  return run;
}

// --- Inputs -----------------------------------------------------------------

/// The finite points of a cloud file: AFSR and the Delaunay triangulation
/// take no NaN, and pcl_ms would leave them out anyway.
bool loadCloud(const std::string &path, const std::string &name, Input &input, std::string &error) {
  pcl::PCLPointCloud2 cloud;
  if (!pcl_ms::loadPointCloud(path, cloud, error))
    return false;
  const std::size_t count = static_cast<std::size_t>(cloud.width) * cloud.height;
  int x = -1;
  for (std::size_t f = 0; f < cloud.fields.size(); ++f)
    if (cloud.fields[f].name == "x")
      x = static_cast<int>(f);
  input.name = name + " (" + path + ")";
  input.xyz.clear();
  input.xyz.reserve(3 * count);
  // loadPointCloud guarantees float32 x, y, z; PCL stores them consecutively.
  for (std::size_t i = 0; i < count; ++i) {
    float point[3];
    std::memcpy(point, &cloud.data[i * cloud.point_step + cloud.fields[x].offset], sizeof point);
    if (std::isfinite(point[0]) && std::isfinite(point[1]) && std::isfinite(point[2]))
      input.xyz.insert(input.xyz.end(), point, point + 3);
  }
  if (input.size() < 4) {
    error = path + ": fewer than 4 finite points";
    return false;
  }
  return true;
}

/// Uniform samples of the surface. The seed depends only on the size so a
/// size gives the same points whichever other sizes are run.
Input sampleSurface(const std::vector<Eigen::Vector3d> &vertices,
                    const std::vector<pcl_ms::Triangle> &triangles, std::size_t size) {
  const std::uint32_t seed = 20240521u + static_cast<std::uint32_t>(size);
  Input input;
  input.name = "bun_zipper surface sample, seed " + std::to_string(seed);
  input.xyz.reserve(3 * size);
  for (const Eigen::Vector3f &point : pcl_ms_tools::sampleSurface(vertices, triangles, size, seed))
    input.xyz.insert(input.xyz.end(), {point.x(), point.y(), point.z()});
  return input;
}

// --- Output -----------------------------------------------------------------

using pcl_ms_tools::withThousands;

const Run *findRun(const std::vector<Run> &runs, const std::string &method) {
  for (const Run &run : runs)
    if (run.method == method && run.measurement.ok)
      return &run;
  return nullptr;
}

bool isPclMs(const std::string &method) { return method.rfind("pcl_ms", 0) == 0; }

void printRatio(const Run &ours, const std::vector<Run> &runs, const std::string &other,
                double baseline_mb) {
  const Run *theirs = findRun(runs, other);
  if (!ours.measurement.ok || !theirs)
    return;
  const double our_extra = ours.peak_mb - baseline_mb;
  const double their_extra = theirs->peak_mb - baseline_mb;
  const auto ratio = [](double a, double b) { return a / std::max(b, 1e-9); };
  std::printf("  %-16s / %-21s time %6.2fx (cpu %5.2fx)   peak memory %5.2fx", ours.method.c_str(),
              other.c_str(), ratio(ours.measurement.seconds, theirs->measurement.seconds),
              ratio(ours.measurement.cpu_seconds, theirs->measurement.cpu_seconds),
              ratio(ours.peak_mb, theirs->peak_mb));
  if (their_extra > 0.5)
    std::printf("   above input %5.2fx", our_extra / their_extra);
  std::printf("\n");
}

void printTable(const Input &input, const std::vector<Run> &runs, double baseline_mb) {
  std::printf("\n== %s: %s points ==\n", input.name.c_str(), withThousands(input.size()).c_str());
  std::printf("  %-22s %10s %10s %11s %12s %12s\n", "method", "time [s]", "cpu [s]", "peak [MB]",
              "above input", "triangles");
  for (const Run &run : runs) {
    if (!run.measurement.ok) {
      std::printf("  %-22s failed: %s\n", run.method.c_str(), run.measurement.message);
      continue;
    }
    if (run.method == "input only") {
      std::printf("  %-22s %10s %10s %11.1f %12s %12s\n", run.method.c_str(), "-", "-", run.peak_mb,
                  "-", "-");
      continue;
    }
    std::printf("  %-22s %10.3f %10.3f %11.1f %12.1f %12s%s\n", run.method.c_str(),
                run.measurement.seconds, run.measurement.cpu_seconds, run.peak_mb,
                run.peak_mb - baseline_mb, withThousands(run.measurement.triangles).c_str(),
                run.method.rfind("Delaunay 3D", 0) == 0 ? " (all facets)" : "");
  }
  for (const Run &ours : runs) {
    if (!isPclMs(ours.method) || !ours.measurement.ok)
      continue;
    const pcl_ms::StageTimings &stages = ours.measurement.stages;
    std::printf("  %s stages [s]: prepare %.3f  delaunay %.3f  scaffold %.3f  greedy %.3f  "
                "finish %.3f  total %.3f\n",
                ours.method.c_str(), stages.prepare, stages.delaunay, stages.scaffold,
                stages.greedy, stages.finish, stages.total);
    const pcl_ms::StagePeakMemory &memory = ours.measurement.stage_memory;
    const double mb = 1024.0 * 1024.0;
    std::printf("  %s process peak after stage [MB]: prepare %.1f  delaunay+scaffold %.1f  "
                "greedy %.1f  finish %.1f\n",
                ours.method.c_str(), memory.prepare / mb, memory.scaffold / mb, memory.greedy / mb,
                memory.finish / mb);
  }
  for (const Run &ours : runs) {
    if (!isPclMs(ours.method))
      continue;
    // Against the peer, and against the floor on as many threads: the whole
    // run, then its own triangulation alone.
    const std::string threads = ours.method.substr(std::string("pcl_ms").size());
    printRatio(ours, runs, "AFSR", baseline_mb);
    printRatio(ours, runs, "Delaunay 3D" + threads, baseline_mb);
    if (const Run *bare = findRun(runs, "Delaunay 3D" + threads))
      if (ours.measurement.ok && bare->measurement.seconds > 0)
        std::printf("  %-16s delaunay stage / %s %.2fx\n", ours.method.c_str(),
                    bare->method.c_str(),
                    ours.measurement.stages.delaunay / bare->measurement.seconds);
  }
  // The peer against the floor, for scale.
  if (const Run *afsr = findRun(runs, "AFSR"))
    printRatio(*afsr, runs, "Delaunay 3D", baseline_mb);
  std::fflush(stdout);
}

void writeCsvRows(std::ofstream &csv, const Input &input, const std::vector<Run> &runs,
                  double baseline_mb) {
  for (const Run &run : runs) {
    const Measurement &m = run.measurement;
    const bool ours = isPclMs(run.method);
    csv << '"' << input.name << "\"," << input.size() << ',' << run.method << ','
        << (m.ok ? "ok" : "failed") << ',' << m.seconds << ',' << m.cpu_seconds << ','
        << run.peak_mb << ',' << run.peak_mb - baseline_mb << ',' << m.triangles;
    if (ours)
      csv << ',' << m.stages.prepare << ',' << m.stages.delaunay << ',' << m.stages.scaffold << ','
          << m.stages.greedy << ',' << m.stages.finish << ',' << m.stages.total;
    else
      csv << ",,,,,,";
    csv << '\n';
  }
  csv.flush();
}

// --- Command line -------------------------------------------------------------

void printHelp(const char *program) {
  std::printf("Times pcl_ms::reconstruct, CGAL's advancing-front reconstruction (AFSR) and a bare\n"
              "CGAL 3-D Delaunay triangulation, each in its own child process.\n\n"
              "Usage: %s [options]\n\n"
              "  -data DIR        sample data directory with bunny.pcd (default: data)\n"
              "  -mesh PATH       reference mesh to sample (default: DIR/bun_zipper.ply)\n"
              "  -clouds F,F,...  more clouds to run (.pcd, .ply, ...; their finite points)\n"
              "  -sizes N,N,...   surface sample sizes, or none (default: 100000,300000,1000000)\n"
              "  -threads N,N,... thread counts for pcl_ms and the bare Delaunay (default: 1)\n"
              "  -one_piece       pcl_ms without buckets, whatever the size\n"
              "  -skip_afsr       do not run AFSR (slow on large inputs)\n"
              "  -afsr_up_to N    run AFSR only on inputs of at most N points (default: all)\n"
              "  -repeat N        run the methods N times in turn and keep each one's fastest run\n"
              "                   (default 1; machines whose speed drifts need 3 or more)\n"
              "  -calls N         call each method N times in its child and keep the fastest\n"
              "                   call: the cost per call of meshing in a loop (default 1)\n"
              "  -csv FILE        also write every measurement to FILE\n"
              "  -h               this help\n",
              program);
}

/// The items of a comma-separated list (an empty text has one empty item).
std::vector<std::string> splitList(const std::string &text) {
  std::vector<std::string> items;
  for (std::size_t start = 0; start <= text.size();) {
    std::size_t end = text.find(',', start);
    if (end == std::string::npos)
      end = text.size();
    items.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return items;
}

bool parseSizes(const std::string &text, std::vector<std::size_t> &sizes, std::size_t minimum = 4) {
  sizes.clear();
  if (text == "none")
    return true;
  for (const std::string &item : splitList(text)) {
    std::size_t value = 0;
    const auto [last, code] = std::from_chars(item.data(), item.data() + item.size(), value);
    if (code != std::errc() || last != item.data() + item.size() || value < minimum)
      return false;
    sizes.push_back(value);
  }
  return true;
}

/// The value of `option`, a whole number from 1 to 100, into `count` (left
/// as it is when the option is absent); false when it is anything else.
bool parseCount(int argc, char **argv, const char *option, int &count) {
  const int at = pcl::console::find_argument(argc, argv, option);
  if (at < 0)
    return true;
  std::vector<std::size_t> values;
  if (!parseSizes(argv[at + 1], values, 1) || values.size() != 1 || values.front() > 100)
    return false;
  count = static_cast<int>(values.front());
  return true;
}

int fail(const std::string &reason) {
  std::fflush(stdout);
  std::fprintf(stderr, "error: %s\n", reason.c_str());
  return 1;
}

} // namespace

int main(int argc, char **argv) {
  if (pcl::console::find_switch(argc, argv, "-h") ||
      pcl::console::find_switch(argc, argv, "--help")) {
    printHelp(argv[0]);
    return 0;
  }
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "-data" || argument == "-mesh" || argument == "-sizes" || argument == "-csv" ||
        argument == "-repeat" || argument == "-threads" || argument == "-clouds" ||
        argument == "-afsr_up_to" || argument == "-calls") {
      if (++i >= argc)
        return fail(argument + " needs a value");
    } else if (argument != "-skip_afsr" && argument != "-one_piece") {
      return fail("unknown argument '" + argument + "' (see -h)");
    }
  }
  std::string data_dir = "data", mesh_path, sizes_text = "100000,300000,1000000", csv_path;
  pcl::console::parse_argument(argc, argv, "-data", data_dir);
  mesh_path = data_dir + "/bun_zipper.ply";
  pcl::console::parse_argument(argc, argv, "-mesh", mesh_path);
  pcl::console::parse_argument(argc, argv, "-sizes", sizes_text);
  pcl::console::parse_argument(argc, argv, "-csv", csv_path);
  std::string threads_text = "1", clouds_text;
  pcl::console::parse_argument(argc, argv, "-threads", threads_text);
  pcl::console::parse_argument(argc, argv, "-clouds", clouds_text);
  const bool skip_afsr = pcl::console::find_switch(argc, argv, "-skip_afsr");
  const bool one_piece = pcl::console::find_switch(argc, argv, "-one_piece");
  std::vector<std::size_t> afsr_limit;
  if (const int at = pcl::console::find_argument(argc, argv, "-afsr_up_to");
      at >= 0 && (!parseSizes(argv[at + 1], afsr_limit, 0) || afsr_limit.size() != 1))
    return fail("-afsr_up_to: expected a number of points");
  std::vector<std::size_t> thread_counts;
  if (!parseSizes(threads_text, thread_counts, 1) || thread_counts.empty())
    return fail("-threads: expected a comma-separated list of numbers >= 1, got '" + threads_text +
                "'");
  const std::vector<std::string> cloud_paths =
      clouds_text.empty() ? std::vector<std::string>() : splitList(clouds_text);
  int repeat = 1, calls = 1; // rounds of all methods; calls of each in its child
  if (!parseCount(argc, argv, "-repeat", repeat))
    return fail("-repeat: expected a number from 1 to 100");
  if (!parseCount(argc, argv, "-calls", calls))
    return fail("-calls: expected a number from 1 to 100");
  std::vector<std::size_t> sizes;
  if (!parseSizes(sizes_text, sizes))
    return fail("-sizes: expected 'none' or a comma-separated list of numbers >= 4, got '" +
                sizes_text + "'");

  std::ofstream csv;
  if (!csv_path.empty()) {
    csv.open(csv_path);
    if (!csv)
      return fail("cannot write " + csv_path);
    csv << "input,points,method,status,time_s,cpu_s,peak_mb,above_input_mb,triangles,"
           "prepare_s,delaunay_s,scaffold_s,greedy_s,finish_s,total_s\n";
  }

  // PCL's readers explain failures on stderr themselves; we print one line.
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  std::string error;
  // An unusable cloud fails before anything else is loaded or run: each is
  // read once here (a file that opens may still not parse or hold too few
  // finite points), and again at its turn, so the parent stays small.
  for (const std::string &path : cloud_paths) {
    Input probe;
    if (!loadCloud(path, "cloud", probe, error))
      return fail("-clouds: " + error);
  }
  Input bunny;
  if (!loadCloud(data_dir + "/bunny.pcd", "bunny vertices", bunny, error))
    return fail(error);
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  if (!sizes.empty() && !pcl_ms::loadMesh(mesh_path, vertices, triangles, error))
    return fail(error);

  std::printf("bench_reconstruct: threads %s%s; each method in a forked child, peak = its "
              "VmHWM.\n'above input' subtracts the peak of a child that only holds the "
              "input. For pcl_ms, the process peak after each stage is printed too.\n",
              threads_text.c_str(), one_piece ? ", pcl_ms in one piece" : "");
  if (repeat > 1)
    std::printf("Each method ran %d times, in turn with the others; its fastest run is shown.\n",
                repeat);
  if (calls > 1)
    std::printf("Each child called its method %d times; times are its fastest call's.\n", calls);
  const std::size_t input_count = 1 + cloud_paths.size() + sizes.size();
  for (std::size_t i = 0; i < input_count; ++i) {
    // Load or sample each input only when its turn comes, so the parent
    // stays small.
    Input other;
    if (i > cloud_paths.size())
      other = sampleSurface(vertices, triangles, sizes[i - 1 - cloud_paths.size()]);
    else if (i > 0 && !loadCloud(cloud_paths[i - 1], "cloud", other, error))
      return fail(error);
    const Input &input = i == 0 ? bunny : other;

    std::vector<std::pair<std::string, std::function<Measurement(const Input &)>>> methods;
    const auto suffix = [](std::size_t threads) {
      return threads == 1 ? std::string() : " " + std::to_string(threads) + " threads";
    };
    for (std::size_t threads : thread_counts)
      methods.emplace_back("pcl_ms" + suffix(threads), [threads, one_piece](const Input &points) {
        return runPclMs(points, static_cast<int>(threads), one_piece);
      });
    if (!skip_afsr && (afsr_limit.empty() || input.size() <= afsr_limit.front()))
      methods.emplace_back("AFSR", runAfsr);
    for (std::size_t threads : thread_counts)
      if (threads == 1)
        methods.emplace_back("Delaunay 3D", runDelaunay);
      else
        methods.emplace_back("Delaunay 3D" + suffix(threads), [threads](const Input &points) {
          return runParallelDelaunay(points, static_cast<int>(threads));
        });

    std::vector<Run> runs;
    runs.push_back(runInChild("input only", runNothing, input));
    const double baseline_mb = runs.back().peak_mb;
    std::vector<Run> fastest(methods.size());
    // Rounds interleave the methods, so a slow spell of the machine hits
    // them alike; each keeps its fastest successful run.
    auto better = [](const Run &run, const Run &best) {
      if (!run.measurement.ok)
        return false;
      return !best.measurement.ok || run.measurement.seconds < best.measurement.seconds;
    };
    for (int round = 0; round < repeat; ++round)
      for (std::size_t m = 0; m < methods.size(); ++m) {
        Run run = runInChild(methods[m].first, methods[m].second, input, calls);
        if (round == 0 || better(run, fastest[m]))
          fastest[m] = std::move(run);
      }
    runs.insert(runs.end(), fastest.begin(), fastest.end());
    printTable(input, runs, baseline_mb);
    if (csv.is_open())
      writeCsvRows(csv, input, runs, baseline_mb);
  }
  return 0;
}
