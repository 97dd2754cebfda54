// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh-quality metrics, first half: the topology of a triangle soup
// (analyzeMesh). In: vertices and index triples, any soup. Out: a
// MeshTopologyReport (components, boundary loops, non-manifold edges and
// vertices, orientability, angles), from a half-edge table built by sorting,
// union-find for components, fans and orientation.
#include <pcl_ms/disjoint_sets.h>
#include <pcl_ms/mesh_quality.h>

#include "mesh_triangles.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>

namespace pcl_ms {
namespace {

using namespace metrics_detail;

constexpr double kPi = 3.14159265358979323846;
constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

// ---------------------------------------------------------------------------
// Small helpers

using pcl_ms::detail::DisjointSets;
using pcl_ms::detail::ParityForest;

// ---------------------------------------------------------------------------
// Topology

/// Undirected edges of the combinatorial part. Half-edge 3t+i runs from
/// triangles[t][i] to triangles[t][(i+1)%3]; half-edges of triangles outside
/// the combinatorial part map to kNone.
struct EdgeTable {
  std::vector<std::size_t> edge_of_halfedge;
  std::vector<std::size_t> halfedges_begin; // edge e owns sorted_halfedges[begin[e], begin[e+1])
  std::vector<std::size_t> sorted_halfedges;
  std::vector<VertexIndex> low_vertex, high_vertex;

  std::size_t size() const { return low_vertex.size(); }
  std::size_t faceCount(std::size_t edge) const {
    return halfedges_begin[edge + 1] - halfedges_begin[edge];
  }
  VertexIndex otherEnd(std::size_t edge, VertexIndex vertex) const {
    return low_vertex[edge] == vertex ? high_vertex[edge] : low_vertex[edge];
  }
};

EdgeTable buildEdgeTable(const std::vector<Triangle> &triangles,
                         const std::vector<char> &in_topology) {
  // Sorting (key, half-edge) pairs is deterministic and cache friendly, and
  // groups all half-edges of an edge together.
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed;
  keyed.reserve(3 * triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    if (!in_topology[t])
      continue;
    for (std::size_t i = 0; i < 3; ++i)
      keyed.emplace_back(edgeKey(triangles[t][i], triangles[t][(i + 1) % 3]), 3 * t + i);
  }
  std::sort(keyed.begin(), keyed.end());

  EdgeTable table;
  table.edge_of_halfedge.assign(3 * triangles.size(), kNone);
  table.sorted_halfedges.reserve(keyed.size());
  for (std::size_t k = 0; k < keyed.size(); ++k) {
    if (k == 0 || keyed[k].first != keyed[k - 1].first) {
      table.halfedges_begin.push_back(k);
      table.low_vertex.push_back(static_cast<VertexIndex>(keyed[k].first >> 32));
      table.high_vertex.push_back(static_cast<VertexIndex>(keyed[k].first & 0xffffffffu));
    }
    table.edge_of_halfedge[keyed[k].second] = table.low_vertex.size() - 1;
    table.sorted_halfedges.push_back(keyed[k].second);
  }
  table.halfedges_begin.push_back(keyed.size());
  return table;
}

void analyzeOrientation(const std::vector<Triangle> &triangles, const EdgeTable &edges,
                        const std::vector<std::size_t> &component_of_triangle,
                        std::size_t component_count, MeshTopologyReport &report) {
  ParityForest orientation(triangles.size());
  std::vector<char> component_broken(component_count, 0);
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (edges.faceCount(e) != 2)
      continue;
    const std::size_t first = edges.sorted_halfedges[edges.halfedges_begin[e]];
    const std::size_t second = edges.sorted_halfedges[edges.halfedges_begin[e] + 1];
    const std::size_t first_triangle = first / 3, second_triangle = second / 3;
    const bool same_direction =
        triangles[first_triangle][first % 3] == triangles[second_triangle][second % 3];
    if (same_direction)
      ++report.inconsistently_oriented_edges;
    // Consistency needs one of the two triangles flipped exactly when both run
    // the edge the same way.
    if (orientation.join(static_cast<std::uint32_t>(first_triangle),
                         static_cast<std::uint32_t>(second_triangle),
                         same_direction) == ParityForest::Join::conflict)
      component_broken[component_of_triangle[first_triangle]] = 1;
  }
  report.non_orientable_components =
      static_cast<std::size_t>(std::count(component_broken.begin(), component_broken.end(), 1));
  report.orientable = report.non_orientable_components == 0;
}

/// Fans around every vertex: non-manifold vertices, and the pairing of
/// boundary edges into curves.
void analyzeVertexFans(const std::vector<Triangle> &triangles, std::size_t vertex_count,
                       const std::vector<char> &in_topology, const EdgeTable &edges,
                       MeshTopologyReport &report) {
  // Corners grouped by vertex (counting sort keeps them in triangle order).
  std::vector<std::size_t> corners_begin(vertex_count + 1, 0);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    if (in_topology[t])
      for (VertexIndex vertex : triangles[t])
        ++corners_begin[vertex + 1];
  std::partial_sum(corners_begin.begin(), corners_begin.end(), corners_begin.begin());
  std::vector<std::size_t> corners(corners_begin.back());
  {
    std::vector<std::size_t> fill = corners_begin;
    for (std::size_t t = 0; t < triangles.size(); ++t)
      if (in_topology[t])
        for (std::size_t i = 0; i < 3; ++i)
          corners[fill[triangles[t][i]]++] = 3 * t + i;
  }

  // Boundary edges paired at both ends trace the curves; an end left without
  // a partner makes its curve an open chain.
  DisjointSets curves(edges.size());
  std::vector<char> has_loose_end(edges.size(), 0);

  struct EdgeAtVertex {
    std::size_t edge, local_triangle;
    bool operator<(const EdgeAtVertex &other) const {
      return std::tie(edge, local_triangle) < std::tie(other.edge, other.local_triangle);
    }
  };
  struct BoundaryAtVertex {
    std::size_t fan;
    VertexIndex far_vertex;
    std::size_t edge;
    bool operator<(const BoundaryAtVertex &other) const {
      return std::tie(fan, far_vertex, edge) < std::tie(other.fan, other.far_vertex, other.edge);
    }
  };
  std::vector<EdgeAtVertex> incident_edges;
  std::vector<BoundaryAtVertex> boundary;
  std::vector<BoundaryAtVertex> unpaired;
  // One forest for every vertex's fans, reset per vertex: sized for the
  // vertex with the most triangles, so the loop allocates nothing.
  std::size_t most_triangles = 0;
  for (std::size_t vertex = 0; vertex < vertex_count; ++vertex)
    most_triangles = std::max(most_triangles, corners_begin[vertex + 1] - corners_begin[vertex]);
  DisjointSets fans(most_triangles);

  for (std::size_t vertex = 0; vertex < vertex_count; ++vertex) {
    const std::size_t begin = corners_begin[vertex], end = corners_begin[vertex + 1];
    if (begin == end)
      continue;
    // Each incident triangle touches two edges at the vertex: the outgoing
    // half-edge of its corner and the incoming one of the previous corner.
    incident_edges.clear();
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t corner = corners[k];
      const std::size_t previous = 3 * (corner / 3) + (corner % 3 + 2) % 3;
      incident_edges.push_back({edges.edge_of_halfedge[corner], k - begin});
      incident_edges.push_back({edges.edge_of_halfedge[previous], k - begin});
    }
    std::sort(incident_edges.begin(), incident_edges.end());

    // Triangles form one fan when linked through edges with two triangles.
    for (std::size_t local = 0; local < end - begin; ++local)
      fans.make_set(local);
    bool on_non_manifold_edge = false;
    for (std::size_t k = 0; k < incident_edges.size();) {
      std::size_t run_end = k + 1;
      while (run_end < incident_edges.size() &&
             incident_edges[run_end].edge == incident_edges[k].edge)
        ++run_end;
      const std::size_t face_count = edges.faceCount(incident_edges[k].edge);
      if (face_count > 2)
        on_non_manifold_edge = true;
      else if (face_count == 2)
        fans.union_set(incident_edges[k].local_triangle, incident_edges[k + 1].local_triangle);
      k = run_end;
    }
    std::size_t fan_count = 0;
    for (std::size_t local = 0; local < end - begin; ++local)
      if (fans.find_set(local) == local)
        ++fan_count;
    if (!on_non_manifold_edge && fan_count > 1)
      ++report.non_manifold_vertices;

    // A fan is a path or a cycle of triangles, so it holds zero, one or two
    // boundary edges at this vertex: two continue each other.
    boundary.clear();
    for (const EdgeAtVertex &incident : incident_edges)
      if (edges.faceCount(incident.edge) == 1)
        boundary.push_back({fans.find_set(incident.local_triangle),
                            edges.otherEnd(incident.edge, static_cast<VertexIndex>(vertex)),
                            incident.edge});
    if (boundary.empty())
      continue;
    std::sort(boundary.begin(), boundary.end());
    unpaired.clear();
    for (std::size_t k = 0; k < boundary.size();) {
      std::size_t run_end = k + 1;
      while (run_end < boundary.size() && boundary[run_end].fan == boundary[k].fan)
        ++run_end;
      if (run_end - k == 2)
        curves.union_set(boundary[k].edge, boundary[k + 1].edge);
      else
        unpaired.insert(unpaired.end(), boundary.begin() + static_cast<std::ptrdiff_t>(k),
                        boundary.begin() + static_cast<std::ptrdiff_t>(run_end));
      k = run_end;
    }
    // Fans cut short by a non-manifold edge: pair what is left by far vertex.
    std::sort(unpaired.begin(), unpaired.end(), [](const auto &a, const auto &b) {
      return std::tie(a.far_vertex, a.edge) < std::tie(b.far_vertex, b.edge);
    });
    for (std::size_t k = 0; k + 1 < unpaired.size(); k += 2)
      curves.union_set(unpaired[k].edge, unpaired[k + 1].edge);
    if (unpaired.size() % 2 == 1)
      has_loose_end[unpaired.back().edge] = 1;
  }

  std::vector<std::size_t> curve_length(edges.size(), 0);
  std::vector<char> curve_open(edges.size(), 0);
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (edges.faceCount(e) != 1)
      continue;
    const std::size_t root = curves.find_set(e);
    ++curve_length[root];
    if (has_loose_end[e])
      curve_open[root] = 1;
  }
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (curve_length[e] == 0)
      continue;
    report.boundary_loop_lengths.push_back(curve_length[e]);
    if (curve_open[e])
      ++report.open_boundary_chains;
  }
  std::sort(report.boundary_loop_lengths.begin(), report.boundary_loop_lengths.end(),
            std::greater<>());
  report.boundary_loops = report.boundary_loop_lengths.size();
}

void analyzeAngles(const std::vector<Eigen::Vector3d> &vertices,
                   const std::vector<Triangle> &triangles, MeshTopologyReport &report) {
  std::vector<double> minimum_angles;
  minimum_angles.reserve(triangles.size());
  for (const Triangle &triangle : triangles) {
    if (!indicesInRange(triangle, vertices.size()))
      continue;
    const double angle =
        minimumAngleDegrees(vertices[triangle[0]], vertices[triangle[1]], vertices[triangle[2]]);
    minimum_angles.push_back(angle);
  }
  if (minimum_angles.empty())
    return;
  const std::size_t below = static_cast<std::size_t>(std::count_if(
      minimum_angles.begin(), minimum_angles.end(), [](double angle) { return angle < 10.0; }));
  report.share_min_angle_below_10deg =
      static_cast<double>(below) / static_cast<double>(minimum_angles.size());
  std::sort(minimum_angles.begin(), minimum_angles.end());
  const std::size_t middle = minimum_angles.size() / 2;
  report.median_min_angle_deg = minimum_angles.size() % 2 == 1
                                    ? minimum_angles[middle]
                                    : 0.5 * (minimum_angles[middle - 1] + minimum_angles[middle]);
}

} // namespace

double minimumAngleDegrees(const Eigen::Vector3d &a, const Eigen::Vector3d &b,
                           const Eigen::Vector3d &c) {
  // atan2(|u x v|, u . v) stays accurate for tiny and obtuse angles, and gives
  // 0 for collinear or coincident corners.
  auto corner = [](const Eigen::Vector3d &apex, const Eigen::Vector3d &p,
                   const Eigen::Vector3d &q) {
    const Eigen::Vector3d u = p - apex, v = q - apex;
    return std::atan2(u.cross(v).norm(), u.dot(v));
  };
  const std::array<double, 3> angles{corner(a, b, c), corner(b, c, a), corner(c, a, b)};
  // Non-finite coordinates, or products overflowing, count as degenerate
  // rather than poisoning the statistics (std::min would skip a NaN).
  for (double angle : angles)
    if (!std::isfinite(angle))
      return 0.0;
  return *std::min_element(angles.begin(), angles.end()) * (180.0 / kPi);
}

MeshTopologyReport analyzeMesh(const std::vector<Eigen::Vector3d> &vertices,
                               const std::vector<Triangle> &triangles) {
  MeshTopologyReport report;
  report.vertices = vertices.size();
  report.triangles = triangles.size();

  std::vector<char> referenced(vertices.size(), 0);
  std::vector<char> in_topology(triangles.size(), 0);
  std::vector<Triangle> sorted_triangles;
  sorted_triangles.reserve(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Triangle &triangle = triangles[t];
    if (!indicesInRange(triangle, vertices.size())) {
      ++report.invalid_triangles;
      continue;
    }
    for (VertexIndex vertex : triangle)
      referenced[vertex] = 1;
    if (isDegenerate(vertices, triangle))
      ++report.degenerate_triangles;
    sorted_triangles.push_back(sortedCorners(triangle));
    in_topology[t] = hasRepeatedIndex(triangle) ? 0 : 1;
  }
  report.referenced_vertices =
      static_cast<std::size_t>(std::count(referenced.begin(), referenced.end(), 1));
  report.used_vertex_fraction = vertices.empty() ? 0.0
                                                 : static_cast<double>(report.referenced_vertices) /
                                                       static_cast<double>(vertices.size());
  // Every copy beyond the first of a vertex set is a duplicate.
  std::sort(sorted_triangles.begin(), sorted_triangles.end());
  report.duplicate_triangles =
      sorted_triangles.size() -
      static_cast<std::size_t>(std::unique(sorted_triangles.begin(), sorted_triangles.end()) -
                               sorted_triangles.begin());
  analyzeAngles(vertices, triangles, report);

  const EdgeTable edges = buildEdgeTable(triangles, in_topology);
  report.edges = edges.size();
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const std::size_t face_count = edges.faceCount(e);
    report.boundary_edges += face_count == 1 ? 1 : 0;
    report.non_manifold_edges += face_count > 2 ? 1 : 0;
  }

  DisjointSets components(triangles.size());
  for (std::size_t e = 0; e < edges.size(); ++e)
    for (std::size_t k = edges.halfedges_begin[e] + 1; k < edges.halfedges_begin[e + 1]; ++k)
      components.union_set(edges.sorted_halfedges[edges.halfedges_begin[e]] / 3,
                           edges.sorted_halfedges[k] / 3);
  std::vector<std::size_t> component_of_triangle(triangles.size(), kNone);
  std::vector<std::size_t> component_of_root(triangles.size(), kNone);
  std::vector<char> vertex_in_topology(vertices.size(), 0);
  std::size_t topology_triangles = 0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    if (!in_topology[t])
      continue;
    ++topology_triangles;
    for (VertexIndex vertex : triangles[t])
      vertex_in_topology[vertex] = 1;
    std::size_t &component = component_of_root[components.find_set(t)];
    if (component == kNone)
      component = report.components++;
    component_of_triangle[t] = component;
  }
  const auto topology_vertices =
      std::count(vertex_in_topology.begin(), vertex_in_topology.end(), 1);
  report.euler_characteristic = static_cast<long long>(topology_vertices) -
                                static_cast<long long>(edges.size()) +
                                static_cast<long long>(topology_triangles);

  analyzeOrientation(triangles, edges, component_of_triangle, report.components, report);
  analyzeVertexFans(triangles, vertices.size(), in_topology, edges, report);
  return report;
}

} // namespace pcl_ms
