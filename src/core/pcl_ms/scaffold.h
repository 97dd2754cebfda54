// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 2 (docs/algorithm.md section 2): the medial scaffold of a point cloud, read off its
// Delaunay tetrahedralisation. Every Delaunay triangle is dual to a Voronoi edge (an A1^3 shock
// curve) and is a candidate surface triangle.
#pragma once

#include <pcl_ms/local_scale.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace pcl_ms {

using CandidateIndex = std::uint32_t;
using EdgeIndex = std::uint32_t;

/// Fig. 10 of the paper: where the shock curve's A1^3-2 point (the triangle's
/// circumcentre) lies.
enum class CandidateType : std::uint8_t {
  acute = 1,    // type I: on the Voronoi edge, inside the triangle
  obtuse = 2,   // type II: on the Voronoi edge, right or obtuse triangle
  ambiguous = 3 // type III: off the Voronoi edge (the triangle is not Gabriel)
};

struct Candidate {
  /// Distinct-point indices, ascending.
  std::array<VertexIndex, 3> vertices;
  /// edges[k] joins vertices[k] and vertices[(k + 1) % 3].
  std::array<EdgeIndex, 3> edges;
  /// eps1 = P / (R C^2), scaled by the normal term when normals are used.
  float base_cost;
  /// 1 / (R C^2), the factor of the context cost eps2.
  float inverse_shock_compactness;
  CandidateType type;
};

/// The edge slot of a candidate whose edges are not numbered yet.
constexpr EdgeIndex no_edge = std::numeric_limits<EdgeIndex>::max();
/// "No such candidate" (never a valid index).
constexpr CandidateIndex no_candidate = std::numeric_limits<CandidateIndex>::max();

/// Candidates below d_max, and which candidates share each edge (CSR).
struct MedialScaffold {
  std::vector<Candidate> candidates;
  /// The edge graph holds the candidates pass 1 looks at: types I and II and
  /// the fixed and preferred ones, ascending on each edge. The other type III
  /// candidates, the majority but rarely kept, wait outside it with edges
  /// no_edge: the greedy's candidate graph (candidate_graph.h) numbers
  /// those that reach pass 2.
  std::vector<std::uint32_t> edge_offsets; // edges + 1 entries
  std::vector<CandidateIndex> edge_candidates;
  /// Edge ids by end points: edge_vertex_offsets[a] is the id of a's first
  /// edge to a higher vertex; ids run on in ascending order of the other end,
  /// which edge_high_vertices holds. One entry per point (+ 1), one per edge.
  std::vector<std::uint32_t> edge_vertex_offsets;
  std::vector<VertexIndex> edge_high_vertices;
  /// The candidates of ScaffoldOptions::fixed_triangles, in the same order.
  std::vector<CandidateIndex> fixed;
  /// The candidates of ScaffoldOptions::preferred_triangles that were kept,
  /// each once, and how many were left out as oversize or degenerate.
  std::vector<CandidateIndex> preferred;
  std::size_t preferred_oversize = 0, preferred_degenerate = 0;

  /// Each point's local scale: the median circumradius of the type I and
  /// II triangles at it. A candidate's sides stay below rho times
  /// triangleScale() of its corners.
  std::vector<float> local_scale;
  double d_med = 0; // median of the local scales (a summary)
  double d_max = 0; // rho * d_med (a summary)
  bool planar = false;
  std::size_t type1 = 0, type2 = 0, type3 = 0;
  std::size_t oversize = 0;   // longest side >= rho * local scale: never queued
  std::size_t degenerate = 0; // collinear generators: never queued
  double delaunay_seconds = 0;
  /// Whether CGAL's parallel insertion built the triangulation (on several
  /// threads); the scaffold is the same either way.
  bool parallel_triangulation = false;

  std::size_t numberOfEdges() const { return edge_offsets.empty() ? 0 : edge_offsets.size() - 1; }
  /// Candidates on edge e, as a [begin, end) pointer range.
  const CandidateIndex *edgeBegin(EdgeIndex e) const {
    return edge_candidates.data() + edge_offsets[e];
  }
  const CandidateIndex *edgeEnd(EdgeIndex e) const {
    return edge_candidates.data() + edge_offsets[e + 1];
  }
  /// The id of the edge joining a and b, or no_edge if it is not in the graph.
  EdgeIndex findEdge(VertexIndex a, VertexIndex b) const {
    if (a > b)
      std::swap(a, b);
    if (a + std::size_t{1} >= edge_vertex_offsets.size())
      return no_edge;
    const auto begin = edge_high_vertices.begin() + edge_vertex_offsets[a];
    const auto end = edge_high_vertices.begin() + edge_vertex_offsets[a + 1];
    const auto it = std::lower_bound(begin, end, b);
    return it != end && *it == b ? static_cast<EdgeIndex>(it - edge_high_vertices.begin())
                                 : no_edge;
  }
};

struct ScaffoldOptions {
  double rho = Parameters().rho;
  int num_threads = 1;
  /// Optional unit normals per point (same indexing as points) and kappa.
  const std::vector<Eigen::Vector3f> *normals = nullptr;
  double normal_weight = 1.0;
  /// d_med to report instead of measuring it (> 0): the buckets and seams
  /// of one cloud share one value.
  double d_med = 0;
  /// Optional local scale per point (same indexing as points): entries > 0
  /// are used as they are instead of being measured here, so that seams
  /// judge their points as the buckets that own them did.
  const std::vector<float> *local_scale = nullptr;
  /// Triangles already in the surface (partial re-meshing, stitching). Each
  /// becomes a candidate even when it is not a Delaunay triangle of these
  /// points or is longer than d_max; the greedy keeps them all.
  const std::vector<Triangle> *fixed_triangles = nullptr;
  /// Triangles the greedy accepts first but may undo (preferred mode of the
  /// initial triangles; distinct, corners ascending). Each becomes a
  /// candidate even when it is not a Delaunay triangle, unless it is oversize
  /// (a side reaching rho times its local scale) or degenerate: those are
  /// left out and counted.
  const std::vector<Triangle> *preferred_triangles = nullptr;
  /// Vertices that only fixed triangles may use (one flag per point).
  const std::vector<bool> *frozen_vertices = nullptr;
};

/// Builds the scaffold of distinct points (at least 3, not all collinear:
/// callers check). Points are expected near the origin (callers centre them)
/// so that floating-point circumcentres stay accurate. Throws
/// ReconstructionError for collinear input. The Delaunay structure is freed
/// before returning: memory afterwards is about the candidates.
MedialScaffold buildMedialScaffold(const std::vector<Eigen::Vector3d> &points,
                                   const ScaffoldOptions &options);

} // namespace pcl_ms
