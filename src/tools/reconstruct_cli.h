// SPDX-License-Identifier: GPL-3.0-or-later
// The command line of pcl_ms_reconstruct: its options, help, progress line
// and report, shared with pcl_ms_reconstruct_mpi so that both take the same
// options and print the same summary.
#pragma once

#include "tool_support.h"

#include <pcl_ms/types.h>

#include <pcl/PCLPointCloud2.h>
#include <pcl/Vertices.h>

#include <chrono>
#include <string>
#include <vector>

namespace pcl_ms_tools {

struct ReconstructOptions {
  std::string input, output;
  // Defaults come from the library so that the tool and the class agree.
  double rho = pcl_ms::Parameters().rho;
  int fill_holes = pcl_ms::Parameters().fill_holes_max_edges;
  bool normals = false;
  int estimate_normals = 0; // neighbours for PCL's normal estimation, 0: none
  double normal_weight = pcl_ms::Parameters().normal_weight;
  bool non_manifold = false; // seams: -non_manifold
  int threads = pcl_ms::Parameters().num_threads;
  unsigned int bucket_points = 0; // 0: automatic
  int grid = 0;
  std::vector<double> viewpoint; // empty, or x, y, z
  bool no_viewpoint = false;
  double time_limit = 0; // seconds, 0: none
  std::string initial;   // a mesh whose triangles start the surface, or empty
  pcl_ms::InitialTrianglesMode initial_mode = pcl_ms::InitialTrianglesMode::fixed;
  std::string medial_axis; // .ply for the medial axis; empty: not computed
  bool quiet = false;
  bool keep_layout = false; // write the cloud's points as they are, NaN rows too
  bool help = false;
};

/// Usage and options; `summary` is the first line (what the program does).
void printReconstructHelp(const char *program, const char *summary);

/// Collects the two file names and checks every option and its value.
bool parseReconstructArguments(int argc, char **argv, ReconstructOptions &options,
                               std::string &error);

/// The library's parameters for the options (no viewpoint from the file
/// yet); an empty string, or why they are invalid.
std::string reconstructParameters(const ReconstructOptions &options,
                                  pcl_ms::Parameters &parameters);

/// kSuccess, or the exit code for an output path that cannot be written
/// (checked before spending time on the reconstruction), with `error` set.
int checkMeshOutput(const std::string &output, std::string &error);

/// As checkMeshOutput, for the -medial_axis file (kSuccess when none).
int checkMedialAxisOutput(const std::string &path, std::string &error);

/// Saves the result's medial axis to options.medial_axis with the "Saving"
/// line; kSuccess (also when none was asked for) or kIoFailure.
int saveReconstructedMedialAxis(const ReconstructOptions &options, const pcl_ms::Result &result,
                                std::string &error);

/// Loads the input, prints the PCL-style "Loading" line and applies the
/// file's viewpoint rule; kSuccess or an exit code with `error` set.
int loadReconstructInput(const ReconstructOptions &options, pcl_ms::Parameters &parameters,
                         pcl::PCLPointCloud2 &cloud, double &load_ms, std::string &error);

/// Reads the triangles of options.initial as indices into `cloud`: each
/// mesh vertex is the input point at the same position (the first, if
/// several are). In preferred mode a triangle with a vertex that is no input
/// point gets an invalid index (the library leaves it out and counts it);
/// in fixed mode that is an error. kSuccess or an exit code with `error` set.
int loadInitialTriangles(const ReconstructOptions &options, const pcl::PCLPointCloud2 &cloud,
                         std::vector<pcl::Vertices> &triangles, std::string &error);

/// Prints the "Reconstructing with ..." line.
void printReconstructStart(const ReconstructOptions &options, const pcl_ms::Parameters &parameters);

/// Saves the mesh (polygons index `cloud`, which it takes over) with the
/// "Saving" line, without the cloud's points that have no position unless
/// `options.keep_layout`; kSuccess or kIoFailure with `error` set.
int saveReconstructedMesh(const ReconstructOptions &options, pcl::PCLPointCloud2 &&cloud,
                          std::vector<pcl::Vertices> &&polygons, double &save_ms,
                          std::string &error);

void printRow(const char *label, const char *format, double value);

/// Timings and summary after a successful run, of `triangles` triangles
/// (result.triangles', unless they were written in runs).
void printReconstructReport(const pcl_ms::Result &result, double load_ms, double save_ms,
                            std::size_t triangles);

/// Buckets and seams done, elapsed time and a linear estimate of the rest:
/// rewritten in place on a terminal, else one line a second.
class ProgressLine {
public:
  void operator()(std::size_t done, std::size_t total);

private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_line_ = start_;
  bool terminal_ = isTerminal();
  bool first_ = true;
  static bool isTerminal();
};

} // namespace pcl_ms_tools
