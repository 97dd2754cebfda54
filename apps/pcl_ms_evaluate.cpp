// SPDX-License-Identifier: GPL-3.0-or-later
// pcl_ms_evaluate: every mesh-quality metric of pcl_ms/mesh_quality.h for any
// mesh file, whichever program made it; optionally against a reference mesh
// and against the point cloud it was made from. Prints a table or JSON. On
// failure it prints one line "error: <reason>" on stderr and exits non-zero
// (1 arguments, 2 files).
#include "mesh_report.h"
#include "tool_support.h"

#include <pcl_ms/io.h>
#include <pcl_ms/mesh_quality.h>

#include <pcl/console/parse.h>

#include <cstdio>
#include <string>
#include <vector>

namespace {

using namespace pcl_ms_tools;

struct Options {
  std::string mesh, reference, points;
  bool json = false;
  bool help = false;
};

void printHelp(const char *program) {
  std::printf(
      "Measures a triangle mesh: topology, manifoldness, triangle shape and, optionally, how\n"
      "it compares with a reference surface and how many points of a cloud it uses.\n\n"
      "Usage: %s mesh [-gt reference] [-points cloud] [-json]\n\n"
      "  mesh            .ply, .obj, .off, .vtk (legacy POLYDATA) or .stl\n"
      "  -gt FILE        reference mesh: triangle recall and precision (vertices matched by\n"
      "                  position), distances in both directions as fractions of the\n"
      "                  reference's bounding-box diagonal, F-scores at 0.1 %% and 0.5 %%\n"
      "  -points FILE    point cloud (.pcd, .ply, .xyz, .txt): share of its finite points\n"
      "                  that are vertices of a triangle, matched by position.\n"
      "                  Positions are compared rounded to float, as PCL stores points (bit\n"
      "                  for bit where rounding would merge two vertices of one file).\n"
      "  -json           print JSON instead of a table\n"
      "  -h              this help\n\n"
      "Exit status: 0 success, 1 bad arguments, 2 file error.\n",
      program);
}

bool parseArguments(int argc, char **argv, Options &options, std::string &error) {
  std::vector<std::string> positional;
  if (!pcl_ms_tools::checkArguments(argc, argv, {"-h", "--help", "-json"}, {"-gt", "-points"},
                                    positional, error))
    return false;
  using pcl::console::find_switch;
  options.help = find_switch(argc, argv, "-h") || find_switch(argc, argv, "--help");
  options.json = find_switch(argc, argv, "-json");
  pcl::console::parse_argument(argc, argv, "-gt", options.reference);
  pcl::console::parse_argument(argc, argv, "-points", options.points);
  if (options.help)
    return true;
  if (positional.size() != 1) {
    error = "expected one mesh file, got " + std::to_string(positional.size()) + " (see -h)";
    return false;
  }
  options.mesh = positional[0];
  return true;
}

void printTable(const char *title, const std::vector<Metric> &metrics) {
  std::printf("\n%s\n", title);
  for (const Metric &metric : metrics)
    std::printf("  %-44s %14s\n", metric.label.c_str(), formatForPeople(metric).c_str());
}

void printJsonObject(const std::vector<Metric> &metrics, const std::string &extra, bool last) {
  std::printf("{\n");
  for (std::size_t i = 0; i < metrics.size(); ++i)
    std::printf("    %s: %s%s\n", jsonString(metrics[i].key).c_str(),
                formatForJson(metrics[i]).c_str(),
                i + 1 < metrics.size() || !extra.empty() ? "," : "");
  if (!extra.empty())
    std::printf("    %s\n", extra.c_str());
  std::printf("  }%s\n", last ? "" : ",");
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

  std::vector<Eigen::Vector3d> vertices, reference_vertices;
  std::vector<pcl_ms::Triangle> triangles, reference_triangles;
  pcl::PointCloud<pcl::PointXYZ> cloud;
  {
    SilencePclMessages silence;
    if (!pcl_ms::loadMesh(options.mesh, vertices, triangles, error))
      return fail(kIoFailure, error);
    if (!options.reference.empty() &&
        !pcl_ms::loadMesh(options.reference, reference_vertices, reference_triangles, error))
      return fail(kIoFailure, error);
    if (!options.points.empty()) {
      pcl::PCLPointCloud2 blob;
      if (!pcl_ms::loadPointCloud(options.points, blob, error))
        return fail(kIoFailure, error);
      finitePoints(blob, cloud);
    }
  }

  const pcl_ms::MeshTopologyReport topology = pcl_ms::analyzeMesh(vertices, triangles);
  pcl_ms::ReferenceReport reference;
  if (!options.reference.empty())
    reference =
        pcl_ms::compareWithReference(vertices, triangles, reference_vertices, reference_triangles);
  PointUsage usage;
  if (!options.points.empty())
    usage = pointsUsedAsVertices(positions(cloud), vertices, triangles);

  if (!options.json) {
    std::printf("Mesh %s: %s vertices, %s triangles\n", options.mesh.c_str(),
                withThousands(vertices.size()).c_str(), withThousands(triangles.size()).c_str());
    printTable("Topology and shape:", topologyMetrics(topology));
    if (!topology.boundary_loop_lengths.empty()) {
      std::string lengths;
      for (std::size_t i = 0; i < topology.boundary_loop_lengths.size() && i < 10; ++i)
        lengths += (i ? ", " : "") + std::to_string(topology.boundary_loop_lengths[i]);
      if (topology.boundary_loop_lengths.size() > 10)
        lengths += ", ...";
      std::printf("  %-44s %s\n", "boundary loop lengths (edges)", lengths.c_str());
    }
    if (!options.reference.empty())
      printTable(("Against the reference " + options.reference + ":").c_str(),
                 referenceMetrics(&reference));
    if (!options.points.empty())
      printTable(("Points of " + options.points + ":").c_str(), pointUsageMetrics(&usage));
    return kSuccess;
  }

  std::string lengths = "\"boundary_loop_lengths\": [";
  for (std::size_t i = 0; i < topology.boundary_loop_lengths.size(); ++i)
    lengths += (i ? ", " : "") + std::to_string(topology.boundary_loop_lengths[i]);
  lengths += "]";
  const bool with_reference = !options.reference.empty(), with_points = !options.points.empty();
  std::printf("{\n  \"mesh\": %s,\n", jsonString(options.mesh).c_str());
  if (with_reference)
    std::printf("  \"reference_file\": %s,\n", jsonString(options.reference).c_str());
  if (with_points)
    std::printf("  \"points_file\": %s,\n", jsonString(options.points).c_str());
  std::printf("  \"topology\": ");
  printJsonObject(topologyMetrics(topology), lengths, !with_reference && !with_points);
  if (with_reference) {
    std::printf("  \"reference\": ");
    printJsonObject(referenceMetrics(&reference), "", !with_points);
  }
  if (with_points) {
    std::printf("  \"points\": ");
    printJsonObject(pointUsageMetrics(&usage), "", true);
  }
  std::printf("}\n");
  return kSuccess;
}

} // namespace

int main(int argc, char **argv) {
  return pcl_ms_tools::runGuarded(run, argc, argv, pcl_ms_tools::kIoFailure);
}
