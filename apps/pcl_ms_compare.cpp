// SPDX-License-Identifier: GPL-3.0-or-later
// pcl_ms_compare: meshes one point cloud with pcl_ms, PCL's greedy projection
// (GP3) and Poisson reconstruction and CGAL's advancing front (AFSR), each in
// its own child process, and writes a table of every mesh-quality metric,
// the meshes and pictures of them. On a failure that stops it, it prints one
// line "error: <reason>" on stderr and exits non-zero (1 arguments, 2 files,
// 3 no method produced a mesh).
#include "child_process.h"
#include "mesh_report.h"
#include "peers.h"
#include "render_mesh.h"
#include "tool_support.h"

#include <pcl_ms/io.h>
#include <pcl_ms/medial_axis.h>
#include <pcl_ms/mesh_quality.h>

#include <pcl/PolygonMesh.h>
#include <pcl/console/parse.h>
#include <pcl/conversions.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using namespace pcl_ms_tools;

struct Options {
  std::string input, reference, out_dir = "compare_out";
  std::vector<Method> methods = allMethods();
  int picture_size = 800;    // pixels, width and height of each method's picture
  bool medial_axis = false;  // also pcl_ms's medial axis: a PLY and a picture
  bool non_manifold = false; // pcl_ms with seams (Parameters::allow_non_manifold)
  bool quiet = false;
  bool help = false;
};

void printHelp(const char *program) {
  std::printf(
      "Meshes a point cloud with pcl_ms and three other methods and compares the results.\n\n"
      "Usage: %s input [-gt reference_mesh] [-out DIR] [-methods list] [-picture_size N]\n"
      "          [-medial_axis] [-non_manifold] [-q]\n\n"
      "  input         point cloud: .pcd, .ply, .xyz or .txt\n"
      "  -gt FILE      reference surface (.ply, .obj, .off, .vtk, .stl): adds triangle\n"
      "                recall and precision (vertices matched by position, rounded to\n"
      "                float as PCL stores points), distances and F-scores\n"
      "  -out DIR      output directory, created if missing (default compare_out)\n"
      "  -methods L    comma-separated subset of pcl_ms (or ours), gp3, poisson, afsr\n"
      "                (default: all four)\n"
      "  -picture_size N\n"
      "                width and height of each method's picture in pixels (default 800)\n"
      "  -medial_axis  also write pcl_ms's medial axis: medial_axis.ply and a picture of its\n"
      "                nodes (those inside, if the surface has an inside) beside the surface\n"
      "  -non_manifold pcl_ms allows non-manifold seams where sheets meet (its pictures draw\n"
      "                edges with three or more triangles red, as every method's do)\n"
      "  -q            quiet: no progress, only warnings and errors\n"
      "  -h            this help\n\n"
      "Writes results.md, results.csv, <method>.ply, <method>.png and side_by_side.png.\n"
      "Each method runs single-threaded in its own child process; its peak memory is that\n"
      "process's VmHWM. GP3 and Poisson get normals from PCL's NormalEstimation (20\n"
      "neighbours) oriented along a minimum spanning tree.\n\n"
      "Exit status: 0 success (also when pictures cannot be made), 1 bad arguments,\n"
      "2 file error, 3 no method produced a mesh.\n",
      program);
}

bool parseMethods(const std::string &text, std::vector<Method> &methods, std::string &error) {
  methods.clear();
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) {
    Method method;
    if (!parseMethod(item, method)) {
      error = "-methods: '" + item + "' is not a method (use pcl_ms, gp3, poisson, afsr)";
      return false;
    }
    if (std::find(methods.begin(), methods.end(), method) != methods.end()) {
      error = "-methods: '" + item + "' is listed twice";
      return false;
    }
    methods.push_back(method);
  }
  if (methods.empty()) {
    error = "-methods: the list is empty";
    return false;
  }
  return true;
}

bool parsePictureSize(const std::string &text, int &size, std::string &error) {
  std::size_t used = 0;
  try {
    size = std::stoi(text, &used);
  } catch (const std::exception &) {
    used = 0;
  }
  if (used == 0 || used != text.size() || size < 64 || size > 4096) {
    error = "-picture_size: '" + text + "' is not a whole number from 64 to 4096";
    return false;
  }
  return true;
}

bool parseArguments(int argc, char **argv, Options &options, std::string &error) {
  std::vector<std::string> positional;
  if (!pcl_ms_tools::checkArguments(
          argc, argv, {"-h", "--help", "-q", "-medial_axis", "-non_manifold"},
          {"-gt", "-out", "-methods", "-picture_size"}, positional, error))
    return false;
  using pcl::console::find_switch;
  using pcl::console::parse_argument;
  options.help = find_switch(argc, argv, "-h") || find_switch(argc, argv, "--help");
  options.quiet = find_switch(argc, argv, "-q");
  options.medial_axis = find_switch(argc, argv, "-medial_axis");
  options.non_manifold = find_switch(argc, argv, "-non_manifold");
  parse_argument(argc, argv, "-gt", options.reference);
  parse_argument(argc, argv, "-out", options.out_dir);
  std::string value;
  if (parse_argument(argc, argv, "-picture_size", value) >= 0 &&
      !parsePictureSize(value, options.picture_size, error))
    return false;
  if (parse_argument(argc, argv, "-methods", value) >= 0 &&
      !parseMethods(value, options.methods, error))
    return false;
  if (options.help)
    return true;
  if (positional.size() != 1) {
    error = "expected one input file, got " + std::to_string(positional.size()) + " (see -h)";
    return false;
  }
  if (options.out_dir.empty()) {
    error = "-out: the directory name is empty";
    return false;
  }
  options.input = positional[0];
  return true;
}

/// One method's run and what was measured on its mesh.
struct Entry {
  PeerRun run;
  pcl_ms::MeshTopologyReport topology;
  std::optional<pcl_ms::ReferenceReport> reference;
  PointUsage usage;
};

std::string printed(const char *format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

std::string stageList(const PeerRun &run, const char *separator, const char *between) {
  std::string text;
  for (const StageTime &stage : run.stages)
    text += (text.empty() ? "" : between) + stage.name + separator + printed("%.3f", stage.seconds);
  return text;
}

/// Rows of the tables: the run itself, then the metrics.
std::vector<Metric> runMetrics(const Entry &entry) {
  Metric time, memory, added;
  time.key = "time_s";
  time.label = "time [s]";
  time.kind = Metric::Kind::seconds;
  time.value = entry.run.seconds();
  memory.key = "peak_mb";
  memory.label = "peak memory [MB]";
  memory.kind = Metric::Kind::megabytes;
  memory.value = entry.run.peak_mb;
  memory.available = entry.run.peak_mb > 0;
  // What the method itself needed, whatever this process held at the fork
  // (that grows as the meshes of earlier methods are kept).
  added.key = "peak_above_start_mb";
  added.label = "peak memory above the child's start [MB]";
  added.kind = Metric::Kind::megabytes;
  added.value = entry.run.peak_mb - entry.run.start_mb;
  added.available = entry.run.peak_mb > 0 && entry.run.start_mb > 0;
  return {time, memory, added};
}

std::vector<Metric> meshMetrics(const Entry &entry, bool with_reference) {
  const bool ok = entry.run.ok;
  std::vector<Metric> rows;
  if (with_reference)
    rows = referenceMetrics(ok && entry.reference ? &*entry.reference : nullptr);
  for (const Metric &m : pointUsageMetrics(ok ? &entry.usage : nullptr))
    rows.push_back(m);
  for (Metric m : topologyMetrics(entry.topology)) {
    m.available = ok;
    rows.push_back(m);
  }
  return rows;
}

bool writeCsv(const std::string &path, const std::vector<Entry> &entries, std::string &error) {
  std::ofstream csv(path);
  if (!csv) {
    error = "cannot write " + path;
    return false;
  }
  // Every column is always there; values a run does not have are empty.
  std::string header = "method,label,status,error,stage_times";
  for (const Metric &m : runMetrics(entries.front()))
    header += "," + m.key;
  for (const Metric &m : meshMetrics(entries.front(), true))
    header += "," + m.key;
  csv << header << ",configuration\n";
  for (const Entry &entry : entries) {
    const PeerRun &run = entry.run;
    csv << methodKey(run.method) << ',' << csvField(methodLabel(run.method)) << ','
        << (run.ok ? "ok" : "failed") << ',' << csvField(run.error) << ','
        << csvField(stageList(run, "=", ";"));
    for (const Metric &m : runMetrics(entry))
      csv << ',' << formatForCsv(m);
    for (const Metric &m : meshMetrics(entry, true))
      csv << ',' << formatForCsv(m);
    csv << ',' << csvField(run.configuration) << '\n';
  }
  csv.close();
  if (!csv) {
    error = "cannot write " + path;
    return false;
  }
  return true;
}

std::string markdownCell(const std::string &text) {
  std::string cell;
  for (char c : text)
    cell += c == '|' ? std::string("\\|") : std::string(1, c);
  return cell;
}

bool writeMarkdown(const std::string &path, const Options &options, std::size_t points,
                   std::size_t skipped, const std::vector<Entry> &entries, double baseline_mb,
                   bool with_reference, std::size_t reference_triangles, std::string &error) {
  std::ofstream md(path);
  if (!md) {
    error = "cannot write " + path;
    return false;
  }
  md << "# Surface reconstruction comparison\n\n";
  md << "Input: `" << options.input << "`, " << withThousands(points) << " points";
  if (skipped > 0)
    md << " (" << withThousands(skipped) << " non-finite points skipped)";
  md << ".  \n";
  if (with_reference)
    md << "Reference: `" << options.reference << "`, " << withThousands(reference_triangles)
       << " triangles.\n\n";
  else
    md << "No reference mesh given (`-gt`): topology and shape only.\n\n";

  md << "| |";
  for (const Entry &entry : entries)
    md << ' ' << methodLabel(entry.run.method) << " |";
  md << "\n|---|";
  for (std::size_t i = 0; i < entries.size(); ++i)
    md << "---|";
  md << "\n| status |";
  for (const Entry &entry : entries)
    md << ' ' << (entry.run.ok ? "ok" : markdownCell("failed: " + entry.run.error)) << " |";
  md << '\n';
  const auto rowsOf = [&](const Entry &entry) {
    std::vector<Metric> rows = runMetrics(entry);
    for (const Metric &m : meshMetrics(entry, with_reference))
      rows.push_back(m);
    return rows;
  };
  const std::vector<Metric> labels = rowsOf(entries.front());
  std::vector<std::vector<Metric>> columns;
  for (const Entry &entry : entries)
    columns.push_back(rowsOf(entry));
  for (std::size_t row = 0; row < labels.size(); ++row) {
    md << "| " << labels[row].label << " |";
    for (const auto &column : columns)
      md << ' ' << formatForPeople(column[row]) << " |";
    md << '\n';
  }

  md << "\n## Stages [s]\n\n";
  for (const Entry &entry : entries)
    md << "- " << methodLabel(entry.run.method) << ": "
       << (entry.run.stages.empty() ? "-" : stageList(entry.run, " ", ", ")) << '\n';
  md << "\n## Configuration\n\n";
  for (const Entry &entry : entries)
    md << "- " << methodLabel(entry.run.method) << ": "
       << (entry.run.configuration.empty() ? "-" : entry.run.configuration) << '\n';
  md << "\n## Notes\n\n"
     << "- Each method ran single-threaded in its own child process. Peak memory is that "
        "process's VmHWM; it includes what the comparing process held when it forked (a child "
        "that does nothing peaks at "
     << printed("%.1f", baseline_mb)
     << " MB), which grows as earlier methods' meshes are kept. The row below it subtracts "
        "the child's resident memory when it started.\n"
     << "- Mesh files: `<method>.ply`. Vertices of pcl_ms, GP3 and AFSR are the input points "
        "in order; Poisson creates new vertices, so no reference triangle or input point "
        "matches them by position and its recall and precision are 0 by construction.\n";
  if (with_reference)
    md << "- Distances are percentages of the reference's bounding-box diagonal, from "
          "area-uniform samples of both surfaces (`pcl_ms::compareWithReference`).\n";
  md.close();
  if (!md) {
    error = "cannot write " + path;
    return false;
  }
  return true;
}

bool saveRunMesh(const std::string &path, const PeerRun &run, std::string &error) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  cloud.reserve(run.vertices.size());
  for (const Eigen::Vector3d &v : run.vertices)
    cloud.emplace_back(static_cast<float>(v.x()), static_cast<float>(v.y()),
                       static_cast<float>(v.z()));
  pcl::PolygonMesh mesh;
  pcl::toPCLPointCloud2(cloud, mesh.cloud);
  mesh.polygons.reserve(run.triangles.size());
  for (const pcl_ms::Triangle &t : run.triangles) {
    pcl::Vertices polygon;
    polygon.vertices = {static_cast<pcl::index_t>(t[0]), static_cast<pcl::index_t>(t[1]),
                        static_cast<pcl::index_t>(t[2])};
    mesh.polygons.push_back(polygon);
  }
  SilencePclMessages silence;
  return pcl_ms::saveMesh(path, mesh, error);
}

/// The medial axis's nodes as small octahedra, so that the mesh renderer can
/// draw them: those inside the surface when it has an inside, else all.
void medialAxisGlyphs(const pcl_ms::MedialAxis &axis, double size,
                      std::vector<Eigen::Vector3d> &vertices,
                      std::vector<pcl_ms::Triangle> &triangles) {
  const bool has_inside =
      std::count(axis.node_side.begin(), axis.node_side.end(), pcl_ms::MedialAxis::inside) > 0;
  for (std::size_t n = 0; n < axis.node_positions.size(); ++n) {
    if (has_inside && axis.node_side[n] != pcl_ms::MedialAxis::inside)
      continue;
    const auto first = static_cast<pcl_ms::VertexIndex>(vertices.size());
    for (int axis_index = 0; axis_index < 3; ++axis_index)
      for (double sign : {1.0, -1.0})
        vertices.push_back(axis.node_positions[n] +
                           sign * size * Eigen::Vector3d::Unit(axis_index));
    // Corners 0/1 on x, 2/3 on y, 4/5 on z; one face per octant, outward.
    for (int x : {0, 1})
      for (int y : {2, 3})
        for (int z : {4, 5}) {
          const bool flip = (x + y + z) % 2 == 1;
          triangles.push_back({first + pcl_ms::VertexIndex(x),
                               first + pcl_ms::VertexIndex(flip ? z : y),
                               first + pcl_ms::VertexIndex(flip ? y : z)});
        }
  }
}

/// Pictures are a bonus: when they cannot be made, say so once and go on.
void writePictures(const fs::path &dir, const std::vector<Eigen::Vector3d> &points,
                   const std::vector<Entry> &entries, int picture_size, bool verbose,
                   const pcl_ms::MedialAxis *medial_axis) {
  const RenderView view = viewFramingPoints(points);
  std::vector<std::string> pictures;
  std::string error;
  for (const Entry &entry : entries) {
    if (!entry.run.ok)
      continue;
    RenderOptions options;
    options.caption = methodLabel(entry.run.method);
    options.width = options.height = picture_size;
    const std::string path = (dir / (methodKey(entry.run.method) + ".png")).string();
    if (!renderMeshPng(entry.run.vertices, entry.run.triangles, view, options, path, error)) {
      std::fflush(stdout);
      std::fprintf(stderr, "warning: pictures not written: %s\n", error.c_str());
      return;
    }
    pictures.push_back(path);
    if (entry.run.method != Method::pcl_ms || !medial_axis)
      continue;
    // pcl_ms's medial axis beside its surface, same camera.
    Eigen::Vector3d low = points.front(), high = points.front();
    for (const Eigen::Vector3d &p : points) {
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    }
    std::vector<Eigen::Vector3d> glyph_vertices;
    std::vector<pcl_ms::Triangle> glyph_triangles;
    medialAxisGlyphs(*medial_axis, 0.003 * (high - low).norm(), glyph_vertices, glyph_triangles);
    options.caption = methodLabel(entry.run.method) + " medial axis";
    const std::string axis_path = (dir / "medial_axis.png").string();
    if (!renderMeshPng(glyph_vertices, glyph_triangles, view, options, axis_path, error)) {
      std::fflush(stdout);
      std::fprintf(stderr, "warning: pictures not written: %s\n", error.c_str());
      return;
    }
    pictures.push_back(axis_path);
  }
  if (pictures.empty())
    return;
  const std::string side_by_side = (dir / "side_by_side.png").string();
  if (!composeSideBySide(pictures, side_by_side, error)) {
    std::fflush(stdout);
    std::fprintf(stderr, "warning: side_by_side.png not written: %s\n", error.c_str());
    return;
  }
  if (verbose)
    std::printf("Pictures: %zu PNGs and side_by_side.png\n", pictures.size());
}

int run(int argc, char **argv) {
  Options options;
  std::string error;
  if (!parseArguments(argc, argv, options, error))
    return fail(kBadArguments, error);
  if (options.help) {
    printHelp(argv[0]);
    return kSuccess;
  }
  const bool verbose = !options.quiet;

  pcl::PCLPointCloud2 blob;
  Eigen::Vector4f sensor_origin;
  {
    SilencePclMessages silence;
    if (!pcl_ms::loadPointCloud(options.input, blob, error, &sensor_origin))
      return fail(kIoFailure, error);
  }
  // A depth frame's sensor is its viewpoint, as for the PCL class.
  PeerSettings settings;
  settings.viewpoint = sensorViewpoint(blob, sensor_origin);
  settings.non_manifold = options.non_manifold;
  pcl::PointCloud<pcl::PointXYZ> points;
  const std::size_t skipped = finitePoints(blob, points);
  blob = pcl::PCLPointCloud2(); // only the positions are needed from here on
  if (points.empty())
    return fail(kReconstructionFailure, options.input + ": no point has finite coordinates");

  std::vector<Eigen::Vector3d> reference_vertices;
  std::vector<pcl_ms::Triangle> reference_triangles;
  const bool with_reference = !options.reference.empty();
  if (with_reference) {
    SilencePclMessages silence;
    if (!pcl_ms::loadMesh(options.reference, reference_vertices, reference_triangles, error))
      return fail(kIoFailure, error);
  }

  const fs::path dir(options.out_dir);
  std::error_code code;
  fs::create_directories(dir, code);
  if (!fs::is_directory(dir, code))
    return fail(kIoFailure, options.out_dir + ": cannot create the output directory");

  if (verbose) {
    std::printf("Input %s: %s points", options.input.c_str(), withThousands(points.size()).c_str());
    if (skipped > 0)
      std::printf(" (%s non-finite skipped)", withThousands(skipped).c_str());
    std::printf("\n");
  }

  // All methods run before anything multi-threaded happens in this process,
  // so every fork starts from a single-threaded parent.
  const double baseline_mb = runInChild([] { return std::string(); }).peak_mb;
  std::vector<Entry> entries;
  const std::size_t total = options.methods.size();
  for (std::size_t i = 0; i < total; ++i) {
    const Method method = options.methods[i];
    const std::string prefix =
        "[" + std::to_string(i + 1) + "/" + std::to_string(total) + "] " + methodLabel(method);
    const auto announce = [&](const std::string &stage) {
      if (verbose) {
        std::printf("%s: %s...\n", prefix.c_str(), stage.c_str());
        std::fflush(stdout);
      }
    };
    Entry entry;
    entry.run = runPeerInChild(method, points, settings, announce);
    if (entry.run.ok) {
      if (verbose)
        std::printf("%s: %s triangles in %.3f s, peak %.1f MB\n", prefix.c_str(),
                    withThousands(entry.run.triangles.size()).c_str(), entry.run.seconds(),
                    entry.run.peak_mb);
    } else {
      std::fflush(stdout);
      std::fprintf(stderr, "warning: %s failed: %s\n", methodLabel(method).c_str(),
                   entry.run.error.c_str());
    }
    entries.push_back(std::move(entry));
  }

  // Files of an earlier run must not pass for this run's (a method that
  // failed now or was not asked for).
  for (Method method : allMethods())
    for (const char *extension : {".ply", ".png"})
      fs::remove(dir / (methodKey(method) + extension), code);
  fs::remove(dir / "side_by_side.png", code);
  fs::remove(dir / "medial_axis.ply", code);
  fs::remove(dir / "medial_axis.png", code);

  const std::vector<Eigen::Vector3d> input_positions = positions(points);
  for (Entry &entry : entries) {
    if (!entry.run.ok)
      continue;
    if (verbose) {
      std::printf("Measuring %s%s...\n", methodLabel(entry.run.method).c_str(),
                  with_reference ? " against the reference" : "");
      std::fflush(stdout);
    }
    entry.topology = pcl_ms::analyzeMesh(entry.run.vertices, entry.run.triangles);
    entry.usage = pointsUsedAsVertices(input_positions, entry.run.vertices, entry.run.triangles);
    if (with_reference)
      entry.reference = pcl_ms::compareWithReference(entry.run.vertices, entry.run.triangles,
                                                     reference_vertices, reference_triangles);
    const std::string mesh_path = (dir / (methodKey(entry.run.method) + ".ply")).string();
    if (!saveRunMesh(mesh_path, entry.run, error))
      return fail(kIoFailure, error);
  }
  std::optional<pcl_ms::MedialAxis> medial_axis;
  for (const Entry &entry : entries)
    if (options.medial_axis && entry.run.ok && entry.run.method == Method::pcl_ms) {
      // The mesh's vertices are the input points, so its own triangles serve.
      medial_axis = pcl_ms::computeMedialAxis(entry.run.vertices, entry.run.triangles);
      if (!pcl_ms::saveMedialAxis((dir / "medial_axis.ply").string(), *medial_axis, error))
        return fail(kIoFailure, error);
      if (verbose)
        std::printf("Medial axis: %s nodes, %s curves\n",
                    withThousands(medial_axis->node_positions.size()).c_str(),
                    withThousands(medial_axis->curves.size()).c_str());
    }

  const std::string csv_path = (dir / "results.csv").string();
  const std::string md_path = (dir / "results.md").string();
  if (!writeCsv(csv_path, entries, error) ||
      !writeMarkdown(md_path, options, points.size(), skipped, entries, baseline_mb, with_reference,
                     reference_triangles.size(), error))
    return fail(kIoFailure, error);
  writePictures(dir, input_positions, entries, options.picture_size, verbose,
                medial_axis ? &*medial_axis : nullptr);
  if (verbose) {
    std::printf("Wrote %s and %s\n", md_path.c_str(), csv_path.c_str());
  }
  const bool any =
      std::any_of(entries.begin(), entries.end(), [](const Entry &entry) { return entry.run.ok; });
  if (!any)
    return fail(kReconstructionFailure, "no method produced a mesh");
  return kSuccess;
}

} // namespace

int main(int argc, char **argv) {
  return pcl_ms_tools::runGuarded(run, argc, argv, pcl_ms_tools::kReconstructionFailure);
}
