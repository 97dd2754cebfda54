// SPDX-License-Identifier: GPL-3.0-or-later
//
// How much of a reference mesh a Delaunay-based method can recover exactly.
// The reference's own vertices are meshed by pcl_ms and by CGAL's advancing
// front; every reference triangle is then classed by where it lies in the
// medial scaffold of those vertices (reference_reach.h), with how many of
// each class either method recovered. On the Stanford bunny this shows the
// ceiling of exact-triangle recall for a method that ranks Gabriel triangles
// first, and how close to it each method gets.
#include "reference_reach.h"
#include "peers.h"
#include "tool_support.h"

#include <pcl_ms/io.h>
#include <pcl_ms/reconstruct.h>

#include <pcl/console/parse.h>
#include <pcl/console/print.h>

#include <cstdio>
#include <string>
#include <vector>

namespace {

using pcl_ms_tools::ReferenceReach;

void printRow(const char *label, std::size_t count, std::size_t total,
              const std::vector<std::size_t> &recovered) {
  std::printf("  %-34s %8zu %7.2f %%", label, count, 100.0 * ReferenceReach::share(count, total));
  for (std::size_t value : recovered)
    std::printf("   %8zu (%6.2f %%)", value, 100.0 * ReferenceReach::share(value, count));
  std::printf("\n");
}

int run(int argc, char **argv) {
  if (pcl::console::find_switch(argc, argv, "-h")) {
    std::printf("usage: %s [reference_mesh] [-rho X]\n"
                "  reference_mesh  .ply/.obj/.off/.vtk whose vertices are meshed (default "
                "%s/bun_zipper.ply)\n"
                "  -rho X          pcl_ms's rho, also the d_max of the classes (default %g)\n",
                argv[0], PCL_MS_DATA_DIR, pcl_ms::Parameters().rho);
    return 0;
  }
  std::vector<int> files = pcl::console::parse_file_extension_argument(argc, argv, ".ply");
  for (const char *extension : {".obj", ".off", ".vtk"})
    for (int index : pcl::console::parse_file_extension_argument(argc, argv, extension))
      files.push_back(index);
  const std::string path =
      files.empty() ? std::string(PCL_MS_DATA_DIR) + "/bun_zipper.ply" : argv[files.front()];
  double rho = pcl_ms::Parameters().rho;
  pcl::console::parse_argument(argc, argv, "-rho", rho);

  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> reference;
  std::string error;
  if (!pcl_ms::loadMesh(path, vertices, reference, error))
    return pcl_ms_tools::fail(1, error);
  pcl::PointCloud<pcl::PointXYZ> points;
  for (const Eigen::Vector3d &v : vertices)
    points.push_back(pcl::PointXYZ(static_cast<float>(v.x()), static_cast<float>(v.y()),
                                   static_cast<float>(v.z())));
  // The methods see float points: class the reference on the same values.
  vertices = pcl_ms_tools::positions(points);

  std::vector<std::string> names = {"pcl_ms"};
  std::vector<ReferenceReach> reaches;
  {
    const pcl_ms::PointView view = pcl_ms_tools::pointView(points);
    pcl_ms::Parameters parameters;
    parameters.rho = rho;
    const pcl_ms::Result result = pcl_ms::reconstruct(view, parameters);
    reaches.push_back(pcl_ms_tools::referenceReach(vertices, reference, result.triangles, rho));
  }
  const pcl_ms_tools::PeerRun afsr =
      pcl_ms_tools::runPeer(pcl_ms_tools::Method::afsr, points, pcl_ms_tools::PeerSettings());
  if (!afsr.ok)
    return pcl_ms_tools::fail(1, "AFSR: " + afsr.error);
  names.push_back("AFSR");
  reaches.push_back(pcl_ms_tools::referenceReach(vertices, reference, afsr.triangles, rho));

  const ReferenceReach &reach = reaches.front();
  std::printf("%s: %zu vertices, %zu reference triangles; classes at rho %g\n", path.c_str(),
              vertices.size(), reach.reference_triangles, rho);
  std::printf("  %-34s %8s %9s", "class of the reference triangle", "count", "share");
  for (const std::string &name : names)
    std::printf("   %-19s", (name + " recovered").c_str());
  std::printf("\n");
  auto column = [&](std::size_t ReferenceReach::*member) {
    std::vector<std::size_t> values;
    for (const ReferenceReach &r : reaches)
      values.push_back(r.*member);
    return values;
  };
  const std::size_t total = reach.reference_triangles;
  printRow("Gabriel (types I and II, pass 1)", reach.gabriel, total,
           column(&ReferenceReach::gabriel_recovered));
  printRow("type III (pass 2 only)", reach.ambiguous, total,
           column(&ReferenceReach::ambiguous_recovered));
  printRow("Delaunay, a side >= d_max", reach.oversize, total,
           column(&ReferenceReach::oversize_recovered));
  printRow("not a Delaunay triangle", reach.not_delaunay, total,
           column(&ReferenceReach::not_delaunay_recovered));
  std::vector<std::size_t> recovered;
  for (const ReferenceReach &r : reaches)
    recovered.push_back(r.gabriel_recovered + r.ambiguous_recovered + r.oversize_recovered +
                        r.not_delaunay_recovered);
  printRow("all (recall)", total, total, recovered);
  return 0;
}

} // namespace

int main(int argc, char **argv) { return pcl_ms_tools::runGuarded(run, argc, argv, 1); }
