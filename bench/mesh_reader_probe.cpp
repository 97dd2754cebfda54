// SPDX-License-Identifier: GPL-3.0-or-later
// mesh_reader_probe: reads every file of some directories with CGAL's
// CGAL::IO::read_polygon_soup and with pcl_ms::loadMesh, each read in a child
// process with a time limit, and counts how each reader ends: a mesh, an
// error, a crash or a hang. Run on the fuzz corpora (garbage that once
// reached new code in our readers) it measures whether CGAL's readers could
// replace ours (issue "Architecture"; results in bench/README.md).
//
//   mesh_reader_probe [-seconds S] DIR...
#include "child_process.h"

#include <pcl_ms/mesh_file.h>

#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Simple_cartesian.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using Point = CGAL::Simple_cartesian<double>::Point_3;

enum class Ending { mesh, error, crash, hang, bad_index };
constexpr std::array<const char *, 5> kEndingNames{"mesh", "error", "crash", "hang", "bad index"};

Ending probe(const std::function<bool()> &read, unsigned seconds) {
  const pcl_ms_tools::ChildOutcome outcome = pcl_ms_tools::runInChild([&] {
    alarm(seconds); // a hang ends with SIGALRM
    return std::string(read() ? "mesh" : "error");
  });
  if (outcome.ok)
    return outcome.payload == "mesh" ? Ending::mesh : Ending::error;
  if (outcome.error.find("face index") != std::string::npos)
    return Ending::bad_index;
  // runInChild names the signal: SIGALRM is "Alarm clock".
  return outcome.error.find("Alarm") != std::string::npos ? Ending::hang : Ending::crash;
}

} // namespace

int main(int argc, char **argv) {
  unsigned seconds = 10;
  std::vector<std::string> directories;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "-seconds" && i + 1 < argc)
      seconds = static_cast<unsigned>(std::max(1, std::atoi(argv[++i])));
    else if (argument == "-h" || argument == "--help" || argument.rfind('-', 0) == 0) {
      std::printf("usage: %s [-seconds S] DIR...\n", argv[0]);
      return argument == "-h" || argument == "--help" ? 0 : 2;
    } else
      directories.push_back(argument);
  }
  // counts[extension][reader][ending]
  std::map<std::string, std::array<std::array<int, 5>, 2>> counts;
  for (const std::string &directory : directories) {
    std::vector<fs::path> files;
    for (const auto &entry : fs::directory_iterator(directory))
      if (entry.is_regular_file())
        files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    // The corpora name files by hash, without extension: the directory says
    // which reader they were made for (mesh_ply, mesh_obj, ...).
    std::string extension = fs::path(directory).filename().string();
    extension = "." + extension.substr(extension.rfind('_') + 1);
    for (const fs::path &file : files) {
      const fs::path copy = fs::temp_directory_path() / ("mesh_reader_probe" + extension);
      fs::copy_file(file, copy, fs::copy_options::overwrite_existing);
      const Ending cgal = probe(
          [&] {
            std::vector<Point> points;
            std::vector<std::vector<std::size_t>> polygons;
            if (!CGAL::IO::read_polygon_soup(copy.string(), points, polygons,
                                             CGAL::parameters::verbose(false)) ||
                polygons.empty())
              return false;
            // A soup whose faces name missing points is no mesh: it would
            // crash whoever indexes with it.
            for (const auto &polygon : polygons)
              for (std::size_t corner : polygon)
                if (corner >= points.size())
                  throw std::runtime_error("face index " + std::to_string(corner) + " of " +
                                           std::to_string(points.size()) + " points");
            return true;
          },
          seconds);
      const Ending ours = probe(
          [&] {
            std::vector<Eigen::Vector3d> vertices;
            std::vector<pcl_ms::Triangle> triangles;
            std::string error;
            return pcl_ms::loadMesh(copy.string(), vertices, triangles, error);
          },
          seconds);
      ++counts[extension][0][static_cast<int>(cgal)];
      ++counts[extension][1][static_cast<int>(ours)];
      if (cgal >= Ending::crash)
        std::printf("CGAL %s: %s\n", kEndingNames[static_cast<int>(cgal)], file.c_str());
      if (ours >= Ending::crash)
        std::printf("pcl_ms %s: %s\n", kEndingNames[static_cast<int>(ours)], file.c_str());
      fs::remove(copy);
    }
  }
  std::printf("\n| format | reader | files | mesh | error | crash | hang | faces naming missing "
              "points |\n|---|---|---|---|---|---|---|---|\n");
  for (const auto &[extension, readers] : counts)
    for (int reader = 0; reader < 2; ++reader) {
      const auto &ending = readers[reader];
      std::printf("| %s | %s | %d | %d | %d | %d | %d | %d |\n", extension.c_str(),
                  reader == 0 ? "CGAL read_polygon_soup" : "pcl_ms::loadMesh",
                  ending[0] + ending[1] + ending[2] + ending[3] + ending[4], ending[0], ending[1],
                  ending[2], ending[3], ending[4]);
    }
  return 0;
}
