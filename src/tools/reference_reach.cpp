// SPDX-License-Identifier: GPL-3.0-or-later
#include "reference_reach.h"

#include <pcl_ms/scaffold.h>

#include <algorithm>
#include <array>
#include <limits>
#include <stdexcept>
#include <string>

namespace pcl_ms_tools {
namespace {

pcl_ms::Triangle sorted(pcl_ms::Triangle triangle) {
  std::sort(triangle.begin(), triangle.end());
  return triangle;
}

std::vector<pcl_ms::Triangle> sortedSet(const std::vector<pcl_ms::Triangle> &triangles,
                                        std::size_t vertex_count) {
  std::vector<pcl_ms::Triangle> set;
  set.reserve(triangles.size());
  for (const pcl_ms::Triangle &triangle : triangles) {
    for (pcl_ms::VertexIndex v : triangle)
      if (v >= vertex_count)
        throw std::invalid_argument("triangle index " + std::to_string(v) + " is out of range");
    set.push_back(sorted(triangle));
  }
  std::sort(set.begin(), set.end());
  set.erase(std::unique(set.begin(), set.end()), set.end());
  return set;
}

bool contains(const std::vector<pcl_ms::Triangle> &set, const pcl_ms::Triangle &triangle) {
  return std::binary_search(set.begin(), set.end(), triangle);
}

} // namespace

ReferenceReach referenceReach(const std::vector<Eigen::Vector3d> &vertices,
                              const std::vector<pcl_ms::Triangle> &reference,
                              const std::vector<pcl_ms::Triangle> &mesh, double rho) {
  // The scaffold wants distinct points near the origin.
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const Eigen::Vector3d &v : vertices) {
    low = low.cwiseMin(v);
    high = high.cwiseMax(v);
  }
  std::vector<Eigen::Vector3d> centred;
  centred.reserve(vertices.size());
  for (const Eigen::Vector3d &v : vertices)
    centred.push_back(v - 0.5 * (low + high));
  {
    std::vector<std::array<double, 3>> coordinates;
    for (const Eigen::Vector3d &v : vertices)
      coordinates.push_back({v.x(), v.y(), v.z()});
    std::sort(coordinates.begin(), coordinates.end());
    if (std::adjacent_find(coordinates.begin(), coordinates.end()) != coordinates.end())
      throw std::invalid_argument("the reference mesh has two vertices at the same position");
  }

  // Candidates at rho, and every Delaunay triangle (rho so large that no
  // side reaches d_max).
  pcl_ms::ScaffoldOptions options;
  options.rho = rho;
  const pcl_ms::MedialScaffold scaffold = pcl_ms::buildMedialScaffold(centred, options);
  options.rho = 1e300;
  options.d_med = scaffold.d_med;
  const pcl_ms::MedialScaffold all_delaunay = pcl_ms::buildMedialScaffold(centred, options);

  std::vector<pcl_ms::Triangle> gabriel, ambiguous, delaunay;
  for (const pcl_ms::Candidate &candidate : scaffold.candidates)
    (candidate.type == pcl_ms::CandidateType::ambiguous ? ambiguous : gabriel)
        .push_back(candidate.vertices);
  for (const pcl_ms::Candidate &candidate : all_delaunay.candidates)
    delaunay.push_back(candidate.vertices);
  for (auto *set : {&gabriel, &ambiguous, &delaunay})
    std::sort(set->begin(), set->end());
  const std::vector<pcl_ms::Triangle> ours = sortedSet(mesh, vertices.size());

  ReferenceReach reach;
  for (const pcl_ms::Triangle &triangle : sortedSet(reference, vertices.size())) {
    ++reach.reference_triangles;
    const bool recovered = contains(ours, triangle);
    if (contains(gabriel, triangle)) {
      ++reach.gabriel;
      reach.gabriel_recovered += recovered;
    } else if (contains(ambiguous, triangle)) {
      ++reach.ambiguous;
      reach.ambiguous_recovered += recovered;
    } else if (contains(delaunay, triangle)) {
      ++reach.oversize;
      reach.oversize_recovered += recovered;
    } else {
      ++reach.not_delaunay;
      reach.not_delaunay_recovered += recovered;
    }
  }
  return reach;
}

} // namespace pcl_ms_tools
