// SPDX-License-Identifier: GPL-3.0-or-later
#include "reconstruct_cli.h"

#include "finite_vertices.h"
#include "normal_estimation.h"
#include "position_keys.h"

#include <pcl_ms/buckets.h>
#include <pcl_ms/io.h>

#include <pcl/PolygonMesh.h>
#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <unordered_map>
#include <utility>

#include <unistd.h>

namespace pcl_ms_tools {

using pcl::console::print_highlight;
using pcl::console::print_info;
using pcl::console::print_value;

namespace {

/// Loads or saves with PCL's own console messages silenced (our one-line
/// error says it all), timing the step and announcing it in PCL tool style.
template <typename Step>
bool fileStep(const char *verb, const std::string &path, bool verbose, double &milliseconds,
              const Step &step) {
  if (verbose) {
    print_highlight("%s ", verb);
    print_value("%s ", path.c_str());
  }
  pcl::console::TicToc timer;
  timer.tic();
  bool succeeded = false;
  {
    SilencePclMessages silence;
    succeeded = step();
  }
  milliseconds = timer.toc();
  if (!succeeded && verbose)
    print_info("[failed]\n");
  return succeeded;
}

std::string fieldNames(const pcl::PCLPointCloud2 &cloud) {
  std::string names;
  for (const pcl::PCLPointField &field : cloud.fields)
    names += (names.empty() ? "" : " ") + field.name;
  return names;
}

} // namespace

void printReconstructHelp(const char *program, const char *summary) {
  print_info("%s\n\n", summary);
  print_info("Usage: %s input output [options]\n\n", program);
  print_info("  input   point cloud: .pcd, .ply, .xyz or .txt (x y z [nx ny nz] per line), or\n"
             "          the vertices of a mesh: .obj, .off, .vtk or .stl\n");
  print_info("  output  mesh: .ply (binary), .vtk or .obj; its vertices are the input points, in\n"
             "          order, with colours and normals where the format can hold them\n\n");
  print_info("Options:\n");
  print_info("  -rho X          no triangle side reaches X times the local scale, the typical\n"
             "                  circumradius of the surface triangles where it lies (default ");
  print_value("%g", pcl_ms::Parameters().rho);
  print_info(")\n");
  print_info("  -fill_holes K   close boundary loops of at most K edges, 0 = off (default ");
  print_value("%d", pcl_ms::Parameters().fill_holes_max_edges);
  print_info(")\n");
  print_info("  -normals        use the cloud's normal_x/y/z fields to guide the surface\n");
  print_info("  -estimate_normals K  estimate normals from each point's K nearest neighbours\n"
             "                  (PCL's NormalEstimation) and use them as -normals does\n");
  print_info("  -normal_weight W  how much disagreeing normals raise a triangle's cost (default ");
  print_value("%g", pcl_ms::Parameters().normal_weight);
  print_info(")\n");
  print_info("  -non_manifold   allow non-manifold seams: a third (fourth...) triangle on an\n"
             "                  edge where sheets meet (default off: a 2-manifold mesh)\n");
  print_info("  -threads N      threads for the parallel stages, 0 = all cores (default ");
  print_value("%d", pcl_ms::Parameters().num_threads);
  print_info(");\n                  one thread for a cloud of under ");
  print_value("%zu", pcl_ms::Parameters().min_points_for_threads);
  print_info(" points in one piece\n");
  print_info("  -bucket_points M  mesh clouds larger than M points in buckets of about M points,\n"
             "                  stitched together; 0 = automatic: buckets of ");
  print_value("%zu", pcl_ms::default_bucket_points);
  print_info(" above ");
  print_value("%zu", pcl_ms::automatic_bucketing_threshold);
  print_info(" points (default 0)\n");
  print_info("  -grid N         cut the bounding box into N x N x N buckets instead; each\n"
             "                  meshes a margin of its neighbours' points too, so buckets of\n"
             "                  far fewer points than the default mesh most points many times\n");
  print_info("  -viewpoint X,Y,Z  where a one-view scan was taken from: open surfaces face it\n"
             "                  and are never left one-sided (default: the sensor origin (PCD\n"
             "                  VIEWPOINT) of an organized cloud, i.e. a depth frame, or a\n"
             "                  non-zero one; none for other clouds)\n");
  print_info("  -no_viewpoint   no viewpoint, even for an organized cloud\n");
  print_info("  -time_limit S   give up after S seconds with an error and no output file,\n"
             "                  0 = no limit (default 0)\n");
  print_info("  -initial MESH   a partial mesh or polygon soup (.ply, .obj, .off, .vtk or\n"
             "                  .stl) whose vertices are input points: its triangles start\n"
             "                  the surface\n");
  print_info("  -initial_mode fixed|preferred  fixed (default): the initial triangles stay and\n"
             "                  must be edge-manifold; preferred: they are accepted first but\n"
             "                  undone where they conflict, so a soup with wrong, overlapping\n"
             "                  or repeated triangles gives a manifold mesh\n");
  print_info("  -keep_layout    write every point of the cloud, in its order and organized\n"
             "                  layout, points without a position (NaN) too (default: those\n"
             "                  are left out of the file, which mesh viewers cannot read)\n");
  print_info("  -medial_axis F.ply  also write the medial axis the surface leaves: its nodes\n"
             "                  (x y z, radius, inside: 1 inside a closed component, 0 outside,\n"
             "                  2 next to an open part) and its curves as edges\n");
  print_info("  -q              quiet: print nothing but errors\n");
  print_info("  -h              this help\n\n");
  print_info("Exit status: 0 success, 1 bad arguments, 2 file error, 3 reconstruction failed.\n");
}

bool parseReconstructArguments(int argc, char **argv, ReconstructOptions &options,
                               std::string &error) {
  const std::vector<std::string> value_options = {
      "-rho",     "-fill_holes",   "-threads",     "-bucket_points",
      "-grid",    "-viewpoint",    "-time_limit",  "-estimate_normals",
      "-initial", "-initial_mode", "-medial_axis", "-normal_weight"};
  std::vector<std::string> positional;
  if (!checkArguments(
          argc, argv,
          {"-h", "--help", "-normals", "-non_manifold", "-q", "-no_viewpoint", "-keep_layout"},
          value_options, positional, error))
    return false;
  using pcl::console::find_switch;
  options.help = find_switch(argc, argv, "-h") || find_switch(argc, argv, "--help");
  options.normals = find_switch(argc, argv, "-normals");
  options.non_manifold = find_switch(argc, argv, "-non_manifold");
  options.quiet = find_switch(argc, argv, "-q");
  options.no_viewpoint = find_switch(argc, argv, "-no_viewpoint");
  options.keep_layout = find_switch(argc, argv, "-keep_layout");
  if (options.help)
    return true;

  // A number option that is absent keeps its default; one given must parse.
  const auto parseNumber = [&](const char *option, auto &value) {
    const int index = pcl::console::find_argument(argc, argv, option);
    if (index < 0 || pcl::console::parse_argument(argc, argv, option, value) >= 0)
      return true;
    error = std::string(option) + ": '" + argv[index + 1] + "' is not a valid number";
    return false;
  };
  if (!parseNumber("-rho", options.rho) || !parseNumber("-fill_holes", options.fill_holes) ||
      !parseNumber("-threads", options.threads) ||
      !parseNumber("-bucket_points", options.bucket_points) || !parseNumber("-grid", options.grid))
    return false;
  if (const int index = pcl::console::find_argument(argc, argv, "-viewpoint"); index >= 0) {
    pcl::console::parse_x_arguments(argc, argv, "-viewpoint", options.viewpoint);
    if (options.viewpoint.size() != 3) {
      error = std::string("-viewpoint: '") + argv[index + 1] + "' is not three numbers x,y,z";
      return false;
    }
  }
  if (!parseNumber("-time_limit", options.time_limit) ||
      !parseNumber("-estimate_normals", options.estimate_normals) ||
      !parseNumber("-normal_weight", options.normal_weight))
    return false;
  if (pcl::console::find_argument(argc, argv, "-estimate_normals") >= 0 &&
      options.estimate_normals < 3) {
    error = "-estimate_normals: at least 3 neighbours are needed (got " +
            std::to_string(options.estimate_normals) + ")";
    return false;
  }
  if (options.normals && options.estimate_normals > 0) {
    error = "-normals and -estimate_normals exclude each other";
    return false;
  }
  pcl::console::parse_argument(argc, argv, "-initial", options.initial);
  if (const int index = pcl::console::find_argument(argc, argv, "-initial_mode"); index >= 0) {
    const std::string mode = argv[index + 1];
    if (mode == "fixed")
      options.initial_mode = pcl_ms::InitialTrianglesMode::fixed;
    else if (mode == "preferred")
      options.initial_mode = pcl_ms::InitialTrianglesMode::preferred;
    else {
      error = "-initial_mode: '" + mode + "' is not fixed or preferred";
      return false;
    }
    if (options.initial.empty()) {
      error = "-initial_mode needs -initial MESH";
      return false;
    }
  }
  pcl::console::parse_argument(argc, argv, "-medial_axis", options.medial_axis);

  if (positional.size() != 2) {
    error = "expected input and output file names, got " + std::to_string(positional.size()) +
            " (see -h)";
    return false;
  }
  options.input = positional[0];
  options.output = positional[1];
  return true;
}

std::string reconstructParameters(const ReconstructOptions &options,
                                  pcl_ms::Parameters &parameters) {
  parameters.rho = options.rho;
  parameters.fill_holes_max_edges = options.fill_holes;
  parameters.use_normals = options.normals || options.estimate_normals > 0;
  parameters.normal_weight = options.normal_weight;
  parameters.num_threads = options.threads;
  parameters.bucket_points = options.bucket_points;
  parameters.grid_buckets = options.grid;
  if (!options.viewpoint.empty())
    parameters.viewpoint = {{options.viewpoint[0], options.viewpoint[1], options.viewpoint[2]}};
  parameters.time_limit_seconds = options.time_limit;
  parameters.initial_triangles_mode = options.initial_mode;
  parameters.compute_medial_axis = !options.medial_axis.empty();
  parameters.allow_non_manifold = options.non_manifold;
  return parameters.validate();
}

/// kSuccess, or kIoFailure when the directory `path` would be written in is missing.
int checkOutputDirectory(const std::string &path, std::string &error) {
  const std::filesystem::path directory = std::filesystem::path(path).parent_path();
  std::error_code code;
  if (!directory.empty() && !std::filesystem::is_directory(directory, code)) {
    error = path + ": directory " + directory.string() + " does not exist";
    return kIoFailure;
  }
  return kSuccess;
}

int checkMeshOutput(const std::string &output, std::string &error) {
  if (!pcl_ms::isMeshOutputSupported(output)) {
    error = output + ": output format '" + pcl_ms::fileExtension(output) +
            "' is not supported (use .ply, .vtk or .obj)";
    return kBadArguments;
  }
  return checkOutputDirectory(output, error);
}

int checkMedialAxisOutput(const std::string &path, std::string &error) {
  if (path.empty())
    return kSuccess;
  if (pcl_ms::fileExtension(path) != ".ply") {
    error = path + ": the medial axis is written as .ply only";
    return kBadArguments;
  }
  return checkOutputDirectory(path, error);
}

int saveReconstructedMedialAxis(const ReconstructOptions &options, const pcl_ms::Result &result,
                                std::string &error) {
  if (options.medial_axis.empty())
    return kSuccess;
  const pcl_ms::MedialAxis none;
  const pcl_ms::MedialAxis &axis = result.medial_axis ? *result.medial_axis : none;
  const bool verbose = !options.quiet;
  double save_ms = 0;
  if (!fileStep("Saving", options.medial_axis, verbose, save_ms,
                [&] { return pcl_ms::saveMedialAxis(options.medial_axis, axis, error); }))
    return kIoFailure;
  if (verbose) {
    print_info("[done, ");
    print_value("%.1f", save_ms);
    print_info(" ms : ");
    print_value("%zu", axis.node_positions.size());
    print_info(" medial axis nodes, ");
    print_value("%zu", axis.curves.size());
    print_info(" curves]\n");
  }
  return kSuccess;
}

int loadReconstructInput(const ReconstructOptions &options, pcl_ms::Parameters &parameters,
                         pcl::PCLPointCloud2 &cloud, double &load_ms, std::string &error) {
  const bool verbose = !options.quiet;
  Eigen::Vector4f sensor_origin;
  if (!fileStep("Loading", options.input, verbose, load_ms, [&] {
        return pcl_ms::loadPointCloud(options.input, cloud, error, &sensor_origin);
      }))
    return kIoFailure;
  if (verbose) {
    print_info("[done, ");
    print_value("%.1f", load_ms);
    print_info(" ms : ");
    print_value("%u", cloud.width * cloud.height);
    print_info(" points]\n");
    print_info("Available dimensions: ");
    print_value("%s\n", fieldNames(cloud).c_str());
  }
  if (!parameters.viewpoint && !options.no_viewpoint)
    parameters.viewpoint = sensorViewpoint(cloud, sensor_origin);
  if (options.estimate_normals > 0) {
    double estimate_ms = 0;
    if (!fileStep("Estimating normals of", options.input, verbose, estimate_ms, [&] {
          return estimateNormals(cloud, options.estimate_normals, parameters.viewpoint, error);
        }))
      return kBadArguments;
    if (verbose) {
      print_info("[done, ");
      print_value("%.1f", estimate_ms);
      print_info(" ms : ");
      print_value("%d", options.estimate_normals);
      print_info(" neighbours]\n");
    }
  }
  if (options.normals && !pcl_ms::hasNormals(cloud)) {
    error = "-normals was given but " + options.input +
            " has no float normal_x, normal_y, normal_z fields";
    return kBadArguments;
  }
  return kSuccess;
}

int loadInitialTriangles(const ReconstructOptions &options, const pcl::PCLPointCloud2 &cloud,
                         std::vector<pcl::Vertices> &triangles, std::string &error) {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> mesh_triangles;
  double load_ms = 0;
  if (!fileStep("Loading", options.initial, !options.quiet, load_ms, [&] {
        return pcl_ms::loadMesh(options.initial, vertices, mesh_triangles, error);
      })) {
    error = "-initial: " + error;
    return kIoFailure;
  }
  pcl::PointCloud<pcl::PointXYZ> points;
  pcl::fromPCLPointCloud2(cloud, points);
  // Input point of each position, the first of repeated ones. The points
  // are floats, so vertices are matched rounded to float (position_keys.h).
  using pcl_ms::metrics_detail::PositionPrecision;
  std::unordered_map<pcl_ms::metrics_detail::PositionKey, pcl::index_t,
                     pcl_ms::metrics_detail::PositionKeyHash>
      point_at;
  point_at.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d point = points[i].getVector3fMap().cast<double>();
    // The reconstruction skips non-finite points, so no vertex may stand on one.
    if (point.allFinite())
      point_at.emplace(pcl_ms::metrics_detail::positionKey(point, PositionPrecision::single),
                       static_cast<pcl::index_t>(i));
  }
  std::vector<pcl::index_t> point_of_vertex(vertices.size(), -1);
  std::size_t unmatched = 0;
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    const auto found =
        point_at.find(pcl_ms::metrics_detail::positionKey(vertices[v], PositionPrecision::single));
    if (found != point_at.end())
      point_of_vertex[v] = found->second;
    else
      ++unmatched;
  }
  triangles.clear();
  triangles.reserve(mesh_triangles.size());
  for (std::size_t t = 0; t < mesh_triangles.size(); ++t) {
    pcl::Vertices polygon;
    for (pcl_ms::VertexIndex v : mesh_triangles[t]) {
      if (point_of_vertex[v] < 0 && options.initial_mode == pcl_ms::InitialTrianglesMode::fixed) {
        error = "-initial: vertex " + std::to_string(v) + " of triangle " + std::to_string(t) +
                " of " + options.initial + " is not a point of " + options.input;
        return kBadArguments;
      }
      polygon.vertices.push_back(point_of_vertex[v]); // -1: left out in preferred mode
    }
    triangles.push_back(std::move(polygon));
  }
  if (!options.quiet) {
    print_info("[done, ");
    print_value("%.1f", load_ms);
    print_info(" ms : ");
    print_value("%zu", triangles.size());
    print_info(" triangles");
    if (unmatched > 0) {
      print_info(", ");
      print_value("%zu", unmatched);
      print_info(" vertices not in the input");
    }
    print_info("]\n");
  }
  return kSuccess;
}

void printReconstructStart(const ReconstructOptions &options,
                           const pcl_ms::Parameters &parameters) {
  print_highlight("Reconstructing with rho ");
  print_value("%g", options.rho);
  print_info(", fill holes ");
  print_value("%d", options.fill_holes);
  print_info(", normals ");
  if (options.estimate_normals > 0)
    print_value("estimated (%d neighbours)", options.estimate_normals);
  else
    print_value("%s", options.normals ? "on" : "off");
  print_info(", threads ");
  print_value("%d", options.threads);
  if (!options.initial.empty()) {
    print_info(", initial triangles ");
    print_value("%s", options.initial_mode == pcl_ms::InitialTrianglesMode::preferred ? "preferred"
                                                                                      : "fixed");
  }
  if (parameters.viewpoint) {
    print_info(", viewpoint ");
    print_value("%g,%g,%g%s", (*parameters.viewpoint)[0], (*parameters.viewpoint)[1],
                (*parameters.viewpoint)[2], options.viewpoint.empty() ? " (sensor origin)" : "");
  }
  print_info(" ");
}

int saveReconstructedMesh(const ReconstructOptions &options, pcl::PCLPointCloud2 &&cloud,
                          std::vector<pcl::Vertices> &&polygons, double &save_ms,
                          std::string &error) {
  pcl::PolygonMesh mesh;
  mesh.polygons = std::move(polygons);
  // The output keeps every field of the user's points, not just x, y, z.
  mesh.header = cloud.header;
  mesh.cloud = std::move(cloud);
  if (!options.keep_layout)
    dropNonFiniteVertices(mesh);
  const bool verbose = !options.quiet;
  if (!fileStep("Saving", options.output, verbose, save_ms,
                [&] { return pcl_ms::saveMesh(options.output, mesh, error); }))
    return kIoFailure;
  if (verbose) {
    print_info("[done, ");
    print_value("%.1f", save_ms);
    print_info(" ms]\n");
  }
  return kSuccess;
}

void printRow(const char *label, const char *format, double value) {
  print_info("  %-22s", label);
  print_value(format, value);
  print_info("\n");
}

void printReconstructReport(const pcl_ms::Result &result, double load_ms, double save_ms,
                            std::size_t triangles) {
  const pcl_ms::StageTimings &timings = result.timings;
  print_info("\nTimings (ms):\n");
  printRow("load", "%10.1f", load_ms);
  printRow("prepare", "%10.1f", timings.prepare * 1e3);
  printRow("delaunay", "%10.1f", timings.delaunay * 1e3);
  printRow("scaffold", "%10.1f", timings.scaffold * 1e3);
  printRow("greedy", "%10.1f", timings.greedy * 1e3);
  printRow("finish", "%10.1f", timings.finish * 1e3);
  if (result.medial_axis)
    printRow("medial axis", "%10.1f", timings.medial_axis * 1e3);
  printRow("total (reconstruction)", "%10.1f", timings.total * 1e3);
  printRow("save", "%10.1f", save_ms);

  print_info("\nSummary:\n");
  printRow("input points", "%10.0f", static_cast<double>(result.input_points));
  printRow("invalid points skipped", "%10.0f", static_cast<double>(result.invalid_points));
  printRow("duplicates merged", "%10.0f", static_cast<double>(result.duplicate_points));
  printRow("far points left out", "%10.0f", static_cast<double>(result.far_points));
  printRow("triangles", "%10.0f", static_cast<double>(triangles));
  printRow("boundary loops", "%10.0f", static_cast<double>(result.boundary_loops.size()));
  printRow("holes filled", "%10.0f", static_cast<double>(result.holes_filled));
  printRow("fold triangles cut", "%10.0f", static_cast<double>(result.twist_triangles_removed));
  if (result.initial_kept + result.initial_duplicates + result.initial_invalid +
          result.initial_oversize >
      0) {
    printRow("initial triangles kept", "%10.0f", static_cast<double>(result.initial_kept));
    printRow("initial repeats merged", "%10.0f", static_cast<double>(result.initial_duplicates));
    printRow("initial invalid", "%10.0f", static_cast<double>(result.initial_invalid));
    printRow("initial oversize", "%10.0f", static_cast<double>(result.initial_oversize));
  }
  if (result.seam_triangles > 0 || !result.seam_edges.empty()) {
    printRow("seam triangles", "%10.0f", static_cast<double>(result.seam_triangles));
    printRow("seam edges", "%10.0f", static_cast<double>(result.seam_edges.size()));
  }
  print_info("  %-22s", "components");
  print_value("%10zu", result.numberOfComponents());
  print_info(" (");
  print_value("%zu", result.numberOfNonOrientableComponents());
  print_info(" non-orientable)\n");
  printRow("d_med", "%10.6g", result.d_med);
  printRow("d_max", "%10.6g", result.d_max);
  if (result.planar)
    print_info("  (all points lie on one plane: a 2-D Delaunay triangulation was used)\n");
  const pcl_ms::BucketStatistics &buckets = result.bucket_statistics;
  if (buckets.buckets > 0) {
    printRow("buckets", "%10.0f", static_cast<double>(buckets.buckets));
    printRow("margin points", "%10.0f", static_cast<double>(buckets.margin_points));
    printRow("seam zones", "%10.0f", static_cast<double>(buckets.seam_zones));
    printRow("seam points", "%10.0f", static_cast<double>(buckets.seam_points));
    printRow("seam triangles", "%10.0f", static_cast<double>(buckets.seam_triangles));
    printRow("buckets (wall ms)", "%10.1f", buckets.buckets_seconds * 1e3);
    printRow("seams (wall ms)", "%10.1f", buckets.seams_seconds * 1e3);
    if (buckets.failed_units > 0)
      printRow("units left empty", "%10.0f", static_cast<double>(buckets.failed_units));
  }
}

void ProgressLine::operator()(std::size_t done, std::size_t total) {
  const auto now = std::chrono::steady_clock::now();
  if (!terminal_ && done != total && now - last_line_ < std::chrono::seconds(1))
    return;
  last_line_ = now;
  if (first_) // the progress starts below the "Reconstructing" line
    std::fprintf(stderr, "\n");
  first_ = false;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double left = done > 0 ? elapsed * static_cast<double>(total - done) / done : 0;
  std::fprintf(stderr, "%s  buckets and seams %zu/%zu, %.1f s elapsed, about %.0f s left%s",
               terminal_ ? "\r" : "", done, total, elapsed, left,
               terminal_ && done != total ? "   " : "\n");
  std::fflush(stderr);
}

bool ProgressLine::isTerminal() { return isatty(fileno(stderr)) != 0; }

} // namespace pcl_ms_tools
