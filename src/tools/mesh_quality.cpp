// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh-quality metrics: topology of a triangle soup (half-edge table built by
// sorting, union-find for components, fans and orientation) and sampled
// distances to a reference mesh through CGAL AABB trees.
#include <pcl_ms/mesh_quality.h>

#include "morton.h"

#include <CGAL/AABB_segment_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Simple_cartesian.h>

#include <Eigen/Geometry>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <tuple>
#include <unordered_map>
#include <utility>

namespace pcl_ms {
namespace {

// Exact predicates for the degeneracy test; plain doubles are enough (and
// faster) for the distance constructions.
using PredicateKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using DistanceKernel = CGAL::Simple_cartesian<double>;
using Point3 = DistanceKernel::Point_3;
using Triangle3 = DistanceKernel::Triangle_3;
using Segment3 = DistanceKernel::Segment_3;
using TrianglePrimitive =
    CGAL::AABB_triangle_primitive<DistanceKernel, std::vector<Triangle3>::const_iterator>;
using SegmentPrimitive =
    CGAL::AABB_segment_primitive<DistanceKernel, std::vector<Segment3>::const_iterator>;
using TriangleTree = CGAL::AABB_tree<CGAL::AABB_traits<DistanceKernel, TrianglePrimitive>>;
using SegmentTree = CGAL::AABB_tree<CGAL::AABB_traits<DistanceKernel, SegmentPrimitive>>;

constexpr double kPi = 3.14159265358979323846;
constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------
// Small helpers

/// Union-find with path halving; the smaller index becomes the root so that
/// roots, and everything numbered by them, do not depend on the union order.
class DisjointSets {
public:
  explicit DisjointSets(std::size_t size = 0) { reset(size); }

  void reset(std::size_t size) {
    parent_.resize(size);
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }

  std::size_t find(std::size_t element) {
    while (parent_[element] != element) {
      parent_[element] = parent_[parent_[element]];
      element = parent_[element];
    }
    return element;
  }

  void unite(std::size_t a, std::size_t b) {
    a = find(a);
    b = find(b);
    if (a == b)
      return;
    if (a < b)
      std::swap(a, b);
    parent_[a] = b;
  }

private:
  std::vector<std::size_t> parent_;
};

/// Union-find that also stores, per element, whether its orientation is
/// flipped relative to its root; used to 2-colour triangles by orientation.
class ParityDisjointSets {
public:
  explicit ParityDisjointSets(std::size_t size) : parent_(size), flipped_(size, 0), size_(size, 1) {
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }

  /// Records that a and b have opposite orientations (differ) or equal ones;
  /// returns false when that contradicts what was recorded before.
  bool relate(std::size_t a, std::size_t b, bool differ) {
    const auto [root_a, parity_a] = find(a);
    const auto [root_b, parity_b] = find(b);
    if (root_a == root_b)
      return (parity_a != parity_b) == differ;
    const auto [big, small] =
        size_[root_a] >= size_[root_b] ? std::pair(root_a, root_b) : std::pair(root_b, root_a);
    parent_[small] = big;
    flipped_[small] = static_cast<char>(parity_a ^ parity_b ^ differ);
    size_[big] += size_[small];
    return true;
  }

private:
  std::pair<std::size_t, bool> find(std::size_t element) {
    std::size_t root = element;
    bool parity = false;
    while (parent_[root] != root) {
      parity ^= flipped_[root] != 0;
      root = parent_[root];
    }
    // Compress the path, keeping each node's parity relative to the root.
    bool node_parity = parity;
    for (std::size_t node = element; parent_[node] != node;) {
      const std::size_t next = parent_[node];
      const bool next_parity = node_parity ^ (flipped_[node] != 0);
      parent_[node] = root;
      flipped_[node] = static_cast<char>(node_parity);
      node = next;
      node_parity = next_parity;
    }
    return {root, parity};
  }

  std::vector<std::size_t> parent_;
  std::vector<char> flipped_;
  std::vector<std::size_t> size_;
};

bool isFinite(const Eigen::Vector3d &point) { return point.allFinite(); }

bool indicesInRange(const Triangle &triangle, std::size_t vertex_count) {
  return triangle[0] < vertex_count && triangle[1] < vertex_count && triangle[2] < vertex_count;
}

bool hasRepeatedIndex(const Triangle &triangle) {
  return triangle[0] == triangle[1] || triangle[1] == triangle[2] || triangle[0] == triangle[2];
}

/// Indices in range is a precondition.
bool isDegenerate(const std::vector<Eigen::Vector3d> &vertices, const Triangle &triangle) {
  if (hasRepeatedIndex(triangle))
    return true;
  const Eigen::Vector3d &a = vertices[triangle[0]];
  const Eigen::Vector3d &b = vertices[triangle[1]];
  const Eigen::Vector3d &c = vertices[triangle[2]];
  // The exact predicate does not accept NaN or infinity.
  if (!isFinite(a) || !isFinite(b) || !isFinite(c))
    return true;
  return CGAL::collinear(PredicateKernel::Point_3(a.x(), a.y(), a.z()),
                         PredicateKernel::Point_3(b.x(), b.y(), b.z()),
                         PredicateKernel::Point_3(c.x(), c.y(), c.z()));
}

std::uint64_t edgeKey(VertexIndex a, VertexIndex b) {
  const VertexIndex low = std::min(a, b);
  const VertexIndex high = std::max(a, b);
  return (static_cast<std::uint64_t>(low) << 32) | high;
}

Triangle sortedCorners(Triangle triangle) {
  std::sort(triangle.begin(), triangle.end());
  return triangle;
}

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
  ParityDisjointSets orientation(triangles.size());
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
    if (!orientation.relate(first_triangle, second_triangle, same_direction))
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
  DisjointSets fans;

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
    fans.reset(end - begin);
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
        fans.unite(incident_edges[k].local_triangle, incident_edges[k + 1].local_triangle);
      k = run_end;
    }
    std::size_t fan_count = 0;
    for (std::size_t local = 0; local < end - begin; ++local)
      if (fans.find(local) == local)
        ++fan_count;
    if (!on_non_manifold_edge && fan_count > 1)
      ++report.non_manifold_vertices;

    // A fan is a path or a cycle of triangles, so it holds zero, one or two
    // boundary edges at this vertex: two continue each other.
    boundary.clear();
    for (const EdgeAtVertex &incident : incident_edges)
      if (edges.faceCount(incident.edge) == 1)
        boundary.push_back({fans.find(incident.local_triangle),
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
        curves.unite(boundary[k].edge, boundary[k + 1].edge);
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
      curves.unite(unpaired[k].edge, unpaired[k + 1].edge);
    if (unpaired.size() % 2 == 1)
      has_loose_end[unpaired.back().edge] = 1;
  }

  std::vector<std::size_t> curve_length(edges.size(), 0);
  std::vector<char> curve_open(edges.size(), 0);
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (edges.faceCount(e) != 1)
      continue;
    const std::size_t root = curves.find(e);
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

// ---------------------------------------------------------------------------
// Comparison with a reference

/// Doubles in [0, 1) from 53 random bits. Written out rather than using
/// std::uniform_real_distribution, whose output differs between standard
/// libraries, so that samples are the same on every platform.
double unitDouble(std::mt19937 &engine) {
  const std::uint64_t high = engine() >> 5; // 27 bits
  const std::uint64_t low = engine() >> 6;  // 26 bits
  return static_cast<double>((high << 26) | low) * 0x1.0p-53;
}

Point3 toPoint(const Eigen::Vector3d &vector) { return {vector.x(), vector.y(), vector.z()}; }

/// Triangles usable for distances: indices in range and finite corners.
std::vector<Triangle> usableTriangles(const std::vector<Eigen::Vector3d> &vertices,
                                      const std::vector<Triangle> &triangles) {
  std::vector<Triangle> usable;
  usable.reserve(triangles.size());
  for (const Triangle &triangle : triangles)
    if (indicesInRange(triangle, vertices.size()) && isFinite(vertices[triangle[0]]) &&
        isFinite(vertices[triangle[1]]) && isFinite(vertices[triangle[2]]))
      usable.push_back(triangle);
  return usable;
}

std::uint64_t mixBits(std::uint64_t value) {
  value ^= value >> 33;
  value *= 0xff51afd7ed558ccdULL;
  value ^= value >> 33;
  value *= 0xc4ceb9fe1a85ec53ULL;
  value ^= value >> 33;
  return value;
}

/// Exact-coordinate key; adding 0.0 turns -0.0 into +0.0 so both compare equal.
struct PositionKey {
  std::uint64_t bits[3];
  bool operator==(const PositionKey &other) const {
    return bits[0] == other.bits[0] && bits[1] == other.bits[1] && bits[2] == other.bits[2];
  }
};

PositionKey positionKey(const Eigen::Vector3d &point) {
  PositionKey key{};
  for (int axis = 0; axis < 3; ++axis) {
    const double value = point[axis] + 0.0;
    std::memcpy(&key.bits[axis], &value, sizeof(value));
  }
  return key;
}

struct PositionKeyHash {
  std::size_t operator()(const PositionKey &key) const {
    return static_cast<std::size_t>(
        mixBits(key.bits[0] ^ mixBits(key.bits[1] ^ mixBits(key.bits[2]))));
  }
};

constexpr VertexIndex kUnmatched = std::numeric_limits<VertexIndex>::max();

/// One id per distinct position over both meshes, reference first: ids below
/// referenceCount() are positions of reference vertices. Exact coincidence
/// of vertices and triangles between the meshes then is integer comparison.
class PositionIds {
public:
  /// Id per vertex used by a usable triangle, kUnmatched for the others.
  std::vector<VertexIndex> assign(const std::vector<Eigen::Vector3d> &vertices,
                                  const std::vector<Triangle> &usable) {
    std::vector<VertexIndex> ids(vertices.size(), kUnmatched);
    for (const Triangle &triangle : usable)
      for (VertexIndex vertex : triangle)
        if (ids[vertex] == kUnmatched)
          ids[vertex] =
              ids_.emplace(positionKey(vertices[vertex]), static_cast<VertexIndex>(ids_.size()))
                  .first->second;
    return ids;
  }
  void closeReference() { reference_count_ = ids_.size(); }
  std::size_t referenceCount() const { return reference_count_; }
  std::size_t size() const { return ids_.size(); }

private:
  std::unordered_map<PositionKey, VertexIndex, PositionKeyHash> ids_;
  std::size_t reference_count_ = 0;
};

/// Nearest reference position within a tolerance: a hash grid with the
/// tolerance as cell size, so candidates lie in the 27 cells around a point.
class ToleranceMatcher {
public:
  ToleranceMatcher(const std::vector<Eigen::Vector3d> &reference_vertices,
                   const std::vector<VertexIndex> &reference_ids, std::size_t id_count,
                   double tolerance)
      : tolerance_(tolerance), positions_(id_count) {
    std::vector<char> stored(id_count, 0);
    for (std::size_t vertex = 0; vertex < reference_vertices.size(); ++vertex) {
      const VertexIndex id = reference_ids[vertex];
      if (id == kUnmatched || stored[id])
        continue; // unused, or a repeat of a position already stored
      stored[id] = 1;
      positions_[id] = reference_vertices[vertex];
      grid_[cellKey(cellOf(reference_vertices[vertex]))].push_back(id);
    }
  }

  VertexIndex match(const Eigen::Vector3d &point) const {
    const std::array<std::int64_t, 3> centre = cellOf(point);
    VertexIndex best = kUnmatched;
    double best_squared = tolerance_ * tolerance_;
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = grid_.find(cellKey({centre[0] + dx, centre[1] + dy, centre[2] + dz}));
          if (it == grid_.end())
            continue;
          for (VertexIndex candidate : it->second) {
            const double squared = (positions_[candidate] - point).squaredNorm();
            // Ties go to the smaller id, so the result does not depend on
            // the order in which cells are visited.
            if (squared < best_squared || (squared == best_squared && candidate < best)) {
              best_squared = squared;
              best = candidate;
            }
          }
        }
    return best;
  }

private:
  std::array<std::int64_t, 3> cellOf(const Eigen::Vector3d &point) const {
    // Clamped so that far-away points cannot overflow the conversion; they
    // only ever share a cell with equally far-away ones.
    constexpr double kLimit = 0x1.0p60;
    std::array<std::int64_t, 3> cell{};
    for (int axis = 0; axis < 3; ++axis)
      cell[static_cast<std::size_t>(axis)] = static_cast<std::int64_t>(
          std::clamp(std::floor(point[axis] / tolerance_), -kLimit, kLimit));
    return cell;
  }

  // Two cells hashing alike only add candidates that the distance test then
  // rejects, so a 64-bit hash of the cell is a safe key.
  static std::uint64_t cellKey(const std::array<std::int64_t, 3> &cell) {
    return mixBits(static_cast<std::uint64_t>(cell[0]) ^
                   mixBits(static_cast<std::uint64_t>(cell[1]) ^
                           mixBits(static_cast<std::uint64_t>(cell[2]))));
  }

  double tolerance_;
  std::vector<Eigen::Vector3d> positions_;
  std::unordered_map<std::uint64_t, std::vector<VertexIndex>> grid_;
};

Triangle keyOf(const Triangle &triangle, const std::vector<VertexIndex> &ids) {
  return sortedCorners({ids[triangle[0]], ids[triangle[1]], ids[triangle[2]]});
}

bool isMatched(const Triangle &key) {
  return key[0] != kUnmatched && key[1] != kUnmatched && key[2] != kUnmatched;
}

/// For each key, whether it occurs in `others` (which gets sorted).
std::vector<char> occursIn(const std::vector<Triangle> &keys, std::vector<Triangle> others) {
  std::sort(others.begin(), others.end());
  std::vector<char> found(keys.size(), 0);
  for (std::size_t i = 0; i < keys.size(); ++i)
    found[i] = isMatched(keys[i]) && std::binary_search(others.begin(), others.end(), keys[i]);
  return found;
}

/// Points on a mesh where distances are measured, with a flag for those
/// known to lie exactly on the other mesh (see Surface::sample).
struct SampleSet {
  std::vector<Point3> points;
  std::vector<char> on_other;
  std::size_t deterministic_count = 0; // the random samples follow these
};

/// A mesh surface prepared for closest-point queries and for sampling.
/// Degenerate triangles are kept as their longest edge in a segment tree:
/// they are part of the surface as a set, and CGAL's point-triangle
/// projection is not reliable for them.
class Surface {
public:
  Surface(const std::vector<Eigen::Vector3d> &vertices, const std::vector<Triangle> &usable)
      : vertices_(vertices), usable_(usable) {
    for (std::size_t t = 0; t < usable.size(); ++t) {
      const Triangle &triangle = usable[t];
      const Eigen::Vector3d &a = vertices[triangle[0]];
      const Eigen::Vector3d &b = vertices[triangle[1]];
      const Eigen::Vector3d &c = vertices[triangle[2]];
      if (!isDegenerate(vertices, triangle)) {
        proper_.emplace_back(toPoint(a), toPoint(b), toPoint(c));
        proper_source_.push_back(t);
        continue;
      }
      const double ab = (b - a).squaredNorm(), bc = (c - b).squaredNorm(),
                   ca = (a - c).squaredNorm();
      if (ab >= bc && ab >= ca)
        collapsed_.emplace_back(toPoint(a), toPoint(b));
      else if (bc >= ca)
        collapsed_.emplace_back(toPoint(b), toPoint(c));
      else
        collapsed_.emplace_back(toPoint(c), toPoint(a));
    }
  }
  Surface(const Surface &) = delete;
  Surface &operator=(const Surface &) = delete;

  bool empty() const { return usable_.empty(); }

  /// Deterministic samples (every referenced vertex, every centroid, every
  /// edge midpoint, so that no triangle, however thin, can fall between the
  /// random samples), then `count` area-uniform random ones. A sample is
  /// flagged as on the other mesh when it comes from a vertex or triangle
  /// that the other mesh has at exactly the same coordinates: its distance
  /// is exactly 0 and needs no query.
  SampleSet sample(const std::vector<char> &vertex_on_other,
                   const std::vector<char> &triangle_on_other, std::size_t count,
                   std::uint32_t seed, std::uint32_t stream) const {
    SampleSet samples;
    std::vector<VertexIndex> used;
    // Edge keys, each with whether its triangle lies on the other mesh.
    std::vector<std::pair<std::uint64_t, bool>> edges;
    used.reserve(3 * usable_.size());
    edges.reserve(3 * usable_.size());
    for (std::size_t t = 0; t < usable_.size(); ++t)
      for (std::size_t i = 0; i < 3; ++i) {
        const VertexIndex from = usable_[t][i], to = usable_[t][(i + 1) % 3];
        used.push_back(from);
        if (from != to)
          edges.emplace_back(edgeKey(from, to), triangle_on_other[t] != 0);
      }
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    // Sorting puts an edge's "on the other mesh" copies last, where the
    // loop below reads them.
    std::sort(edges.begin(), edges.end());

    const std::size_t expected = used.size() + usable_.size() + edges.size() + count;
    samples.points.reserve(expected);
    samples.on_other.reserve(expected);
    for (VertexIndex vertex : used) {
      samples.points.push_back(toPoint(vertices_[vertex]));
      samples.on_other.push_back(vertex_on_other[vertex]);
    }
    for (std::size_t t = 0; t < usable_.size(); ++t) {
      const Triangle &triangle = usable_[t];
      samples.points.push_back(toPoint(
          (vertices_[triangle[0]] + vertices_[triangle[1]] + vertices_[triangle[2]]) / 3.0));
      samples.on_other.push_back(triangle_on_other[t]);
    }
    for (std::size_t k = 0; k < edges.size(); ++k) {
      if (k + 1 < edges.size() && edges[k + 1].first == edges[k].first)
        continue;
      const std::uint64_t key = edges[k].first;
      samples.points.push_back(
          toPoint(0.5 * (vertices_[key >> 32] + vertices_[key & 0xffffffffu])));
      samples.on_other.push_back(edges[k].second);
    }
    samples.deterministic_count = samples.points.size();
    appendRandomSamples(triangle_on_other, count, seed, stream, samples);
    return samples;
  }

  /// Distance from every sample to this surface. Queries go in Morton order
  /// in fixed blocks, each query using the previous closest point as its
  /// hint; blocks are spread over threads. Blocks do not depend on the
  /// thread count, so neither do the results.
  std::vector<double> distances(const SampleSet &samples) {
    std::vector<double> result(samples.points.size(), 0.0);
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < samples.points.size(); ++i)
      if (!samples.on_other[i])
        order.push_back(i);
    if (order.empty())
      return result; // a mesh compared with itself needs no tree at all
    buildTrees();
    sortAlongMortonCurve(samples.points, order);

    constexpr std::size_t kBlock = 256;
    const std::size_t block_count = (order.size() + kBlock - 1) / kBlock;
    // TBB, like the reconstruction: the caller's task arena (and its thread
    // limit) applies. Each block has its own hints and writes its own
    // entries, so the result does not depend on the scheduling.
    tbb::parallel_for(std::size_t{0}, block_count, [&](std::size_t block) {
      Hints hints;
      const std::size_t end = std::min(order.size(), (block + 1) * kBlock);
      for (std::size_t k = block * kBlock; k < end; ++k)
        result[order[k]] = std::sqrt(squaredDistance(samples.points[order[k]], hints));
    });
    return result;
  }

private:
  struct Hints {
    std::optional<Point3> triangle, segment;
  };

  /// Trees and their search hints are built before any query: queries then
  /// only read them, which lets several threads share them.
  void buildTrees() {
    if (!proper_.empty() && triangle_tree_.empty()) {
      triangle_tree_.insert(proper_.begin(), proper_.end());
      triangle_tree_.build();
      triangle_tree_.accelerate_distance_queries();
    }
    if (!collapsed_.empty() && segment_tree_.empty()) {
      segment_tree_.insert(collapsed_.begin(), collapsed_.end());
      segment_tree_.build();
      segment_tree_.accelerate_distance_queries();
    }
  }

  double squaredDistance(const Point3 &query, Hints &hints) const {
    double best = kInfinity;
    if (!proper_.empty()) {
      hints.triangle = hints.triangle ? triangle_tree_.closest_point(query, *hints.triangle)
                                      : triangle_tree_.closest_point(query);
      best = CGAL::squared_distance(query, *hints.triangle);
    }
    if (!collapsed_.empty()) {
      hints.segment = hints.segment ? segment_tree_.closest_point(query, *hints.segment)
                                    : segment_tree_.closest_point(query);
      best = std::min(best, CGAL::squared_distance(query, *hints.segment));
    }
    return best;
  }

  static void sortAlongMortonCurve(const std::vector<Point3> &points,
                                   std::vector<std::size_t> &order) {
    if (order.empty())
      return;
    Eigen::Vector3d low = Eigen::Vector3d::Constant(kInfinity), high = -low;
    for (std::size_t index : order) {
      const Eigen::Vector3d point(points[index].x(), points[index].y(), points[index].z());
      low = low.cwiseMin(point);
      high = high.cwiseMax(point);
    }
    const double extent = std::max((high - low).maxCoeff(), std::numeric_limits<double>::min());
    const double cells = static_cast<double>((1 << 21) - 1);
    std::vector<std::pair<std::uint64_t, std::size_t>> coded;
    coded.reserve(order.size());
    for (std::size_t index : order) {
      std::uint32_t cell[3];
      for (int axis = 0; axis < 3; ++axis) {
        const double scaled = (points[index][axis] - low[axis]) / extent * cells;
        cell[axis] = static_cast<std::uint32_t>(std::clamp(scaled, 0.0, cells));
      }
      coded.emplace_back(detail::mortonCode(cell[0], cell[1], cell[2]), index);
    }
    std::sort(coded.begin(), coded.end());
    for (std::size_t k = 0; k < coded.size(); ++k)
      order[k] = coded[k].second;
  }

  void appendRandomSamples(const std::vector<char> &triangle_on_other, std::size_t count,
                           std::uint32_t seed, std::uint32_t stream, SampleSet &samples) const {
    std::vector<double> cumulative_area;
    cumulative_area.reserve(proper_.size());
    double total = 0;
    for (const Triangle3 &triangle : proper_) {
      total += std::sqrt(triangle.squared_area());
      cumulative_area.push_back(total);
    }
    if (count == 0 || !(total > 0))
      return;
    std::seed_seq seeds{seed, stream};
    std::mt19937 engine(seeds);
    for (std::size_t n = 0; n < count; ++n) {
      const double target = unitDouble(engine) * total;
      const std::size_t index = std::min<std::size_t>(
          static_cast<std::size_t>(
              std::upper_bound(cumulative_area.begin(), cumulative_area.end(), target) -
              cumulative_area.begin()),
          proper_.size() - 1);
      // sqrt makes the density uniform over the triangle's area.
      const double radial = std::sqrt(unitDouble(engine));
      const double across = unitDouble(engine);
      const Triangle3 &triangle = proper_[index];
      samples.points.push_back(triangle[0] + radial * (1.0 - across) * (triangle[1] - triangle[0]) +
                               radial * across * (triangle[2] - triangle[0]));
      samples.on_other.push_back(triangle_on_other[proper_source_[index]]);
    }
  }

  const std::vector<Eigen::Vector3d> &vertices_;
  const std::vector<Triangle> &usable_;
  std::vector<Triangle3> proper_;
  std::vector<std::size_t> proper_source_; // index into usable_
  std::vector<Segment3> collapsed_;
  TriangleTree triangle_tree_;
  SegmentTree segment_tree_;
};

/// Distances of one direction, normalised by the reference diagonal, and the
/// range the statistics use: every sample, or the area-uniform ones only.
struct SampledDistances {
  std::vector<double> distances; // deterministic samples first, random ones after
  std::size_t statistics_begin = 0;

  double shareWithin(double tolerance) const {
    const auto begin = distances.begin() + static_cast<std::ptrdiff_t>(statistics_begin);
    const auto within = std::count_if(
        begin, distances.end(), [tolerance](double distance) { return distance <= tolerance; });
    return static_cast<double>(within) / static_cast<double>(distances.end() - begin);
  }

  DistanceStats stats() const {
    DistanceStats result;
    result.max = *std::max_element(distances.begin(), distances.end());
    std::vector<double> tail(distances.begin() + static_cast<std::ptrdiff_t>(statistics_begin),
                             distances.end());
    result.mean = std::accumulate(tail.begin(), tail.end(), 0.0) / static_cast<double>(tail.size());
    // Nearest rank: the smallest value with at least 95 % of them at or below it.
    const auto rank = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(tail.size())));
    const auto nth = tail.begin() + static_cast<std::ptrdiff_t>(std::max<std::size_t>(rank, 1) - 1);
    std::nth_element(tail.begin(), nth, tail.end());
    result.p95 = *nth;
    return result;
  }
};

SampledDistances measure(const SampleSet &samples, Surface &to, const ReferenceOptions &options,
                         double scale) {
  SampledDistances result;
  result.distances = to.distances(samples);
  for (double &distance : result.distances)
    distance /= scale;
  if (options.area_weighted_statistics && samples.points.size() > samples.deterministic_count)
    result.statistics_begin = samples.deterministic_count;
  return result;
}

double fscore(double precision, double recall) {
  return precision + recall > 0 ? 2 * precision * recall / (precision + recall) : 0.0;
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
      components.unite(edges.sorted_halfedges[edges.halfedges_begin[e]] / 3,
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
    std::size_t &component = component_of_root[components.find(t)];
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

ReferenceReport compareWithReference(const std::vector<Eigen::Vector3d> &vertices,
                                     const std::vector<Triangle> &triangles,
                                     const std::vector<Eigen::Vector3d> &reference_vertices,
                                     const std::vector<Triangle> &reference_triangles,
                                     const ReferenceOptions &options) {
  ReferenceReport report;
  report.triangles = triangles.size();
  report.reference_triangles = reference_triangles.size();
  const std::vector<Triangle> usable = usableTriangles(vertices, triangles);
  const std::vector<Triangle> reference_usable =
      usableTriangles(reference_vertices, reference_triangles);

  if (!reference_usable.empty()) {
    Eigen::Vector3d low = reference_vertices[reference_usable.front()[0]], high = low;
    for (const Triangle &triangle : reference_usable)
      for (VertexIndex vertex : triangle) {
        low = low.cwiseMin(reference_vertices[vertex]);
        high = high.cwiseMax(reference_vertices[vertex]);
      }
    report.reference_diagonal = (high - low).norm();
  }

  // Exact coincidence, as triples of shared position ids.
  PositionIds positions;
  const std::vector<VertexIndex> reference_ids =
      positions.assign(reference_vertices, reference_usable);
  positions.closeReference();
  const std::vector<VertexIndex> our_ids = positions.assign(vertices, usable);
  std::vector<Triangle> reference_keys, our_exact_keys;
  reference_keys.reserve(reference_usable.size());
  our_exact_keys.reserve(usable.size());
  for (const Triangle &triangle : reference_usable)
    reference_keys.push_back(keyOf(triangle, reference_ids));
  for (const Triangle &triangle : usable)
    our_exact_keys.push_back(keyOf(triangle, our_ids));

  // Triangle recovery: with a tolerance, our vertices are first moved onto
  // the ids of their nearest reference positions. Ids from
  // referenceCount() on are positions the reference does not have.
  std::vector<Triangle> our_match_keys = our_exact_keys;
  if (options.position_tolerance > 0) {
    const ToleranceMatcher matcher(reference_vertices, reference_ids, positions.referenceCount(),
                                   options.position_tolerance);
    std::vector<VertexIndex> matched(vertices.size(), kUnmatched);
    for (std::size_t vertex = 0; vertex < vertices.size(); ++vertex)
      if (our_ids[vertex] != kUnmatched)
        matched[vertex] = matcher.match(vertices[vertex]);
    for (std::size_t t = 0; t < usable.size(); ++t)
      our_match_keys[t] = keyOf(usable[t], matched);
  }
  const std::vector<char> recovered = occursIn(reference_keys, our_match_keys);
  const std::vector<char> in_reference = occursIn(our_match_keys, reference_keys);
  report.recovered_reference_triangles =
      static_cast<std::size_t>(std::count(recovered.begin(), recovered.end(), 1));
  report.triangles_in_reference =
      static_cast<std::size_t>(std::count(in_reference.begin(), in_reference.end(), 1));
  if (report.reference_triangles > 0)
    report.recall = static_cast<double>(report.recovered_reference_triangles) /
                    static_cast<double>(report.reference_triangles);
  if (report.triangles > 0)
    report.precision =
        static_cast<double>(report.triangles_in_reference) / static_cast<double>(report.triangles);

  Surface ours(vertices, usable);
  Surface reference(reference_vertices, reference_usable);
  if (ours.empty() || reference.empty()) {
    report.to_reference = report.from_reference = {kInfinity, kInfinity, kInfinity};
    return report;
  }

  // What lies exactly on the other mesh needs no distance query.
  std::vector<char> our_vertex_on_reference(vertices.size(), 0);
  std::vector<char> position_in_ours(positions.size(), 0);
  for (std::size_t vertex = 0; vertex < vertices.size(); ++vertex)
    if (our_ids[vertex] != kUnmatched) {
      our_vertex_on_reference[vertex] = our_ids[vertex] < positions.referenceCount();
      position_in_ours[our_ids[vertex]] = 1;
    }
  std::vector<char> reference_vertex_on_ours(reference_vertices.size(), 0);
  for (std::size_t vertex = 0; vertex < reference_vertices.size(); ++vertex)
    if (reference_ids[vertex] != kUnmatched)
      reference_vertex_on_ours[vertex] = position_in_ours[reference_ids[vertex]];
  const std::vector<char> our_triangle_on_reference = occursIn(our_exact_keys, reference_keys);
  const std::vector<char> reference_triangle_on_ours = occursIn(reference_keys, our_exact_keys);

  // Separate random streams so the two meshes are not sampled in lockstep.
  const SampleSet our_samples = ours.sample(our_vertex_on_reference, our_triangle_on_reference,
                                            options.surface_samples, options.seed, 0);
  const SampleSet reference_samples =
      reference.sample(reference_vertex_on_ours, reference_triangle_on_ours,
                       options.surface_samples, options.seed, 1);
  const double scale = report.reference_diagonal > 0 ? report.reference_diagonal : 1.0;
  const SampledDistances to_reference = measure(our_samples, reference, options, scale);
  const SampledDistances from_reference = measure(reference_samples, ours, options, scale);
  report.to_reference = to_reference.stats();
  report.from_reference = from_reference.stats();
  // With a zero diagonal the distances are absolute and tau is 0.
  const double tau_fine = report.reference_diagonal > 0 ? 0.001 : 0.0;
  const double tau_coarse = report.reference_diagonal > 0 ? 0.005 : 0.0;
  report.fscore_0_1 =
      fscore(to_reference.shareWithin(tau_fine), from_reference.shareWithin(tau_fine));
  report.fscore_0_5 =
      fscore(to_reference.shareWithin(tau_coarse), from_reference.shareWithin(tau_coarse));
  return report;
}

} // namespace pcl_ms
