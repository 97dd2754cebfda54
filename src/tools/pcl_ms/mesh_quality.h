// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh-quality metrics: combinatorial topology of a triangle soup and its
// distance to a reference mesh. Used by the tests to assert reconstruction
// quality and by the comparison tools; independent of the reconstruction.
#pragma once

#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pcl_ms {

/// Topology and shape of a mesh given as vertex positions plus index triples.
///
/// Which triangles count where:
///  - A triangle with an index >= vertices.size() is "invalid": it is counted in
///    `triangles` and `invalid_triangles` and ignored everywhere else.
///  - Every valid triangle enters referenced_vertices, the duplicate count and
///    the angle statistics (a degenerate triangle has a minimum angle of 0).
///  - The combinatorial part (edges, boundary, manifoldness, components, Euler
///    characteristic, orientation) uses the valid triangles with three distinct
///    indices, i.e. the mesh as given, including zero-area and duplicate
///    triangles: those really are in the mesh and do change its topology (a
///    duplicate of an interior triangle makes its three edges non-manifold).
///    A triangle with a repeated index is not a 2-cell and is left out.
///
/// Manifoldness is reported by two independent counters: an edge is
/// non-manifold when it has more than two triangles; a vertex is non-manifold
/// when it lies on no non-manifold edge and its triangles still do not form a
/// single fan (a "pinch", e.g. two cones touching at their tips). Vertices on a
/// non-manifold edge are left to the edge counter so one defect is not counted
/// twice; the mesh is a 2-manifold with boundary exactly when both are zero.
struct MeshTopologyReport {
  std::size_t vertices = 0;            // size of the vertex array
  std::size_t referenced_vertices = 0; // used by at least one valid triangle
  std::size_t triangles = 0;           // size of the triangle array
  std::size_t invalid_triangles = 0;   // with an index out of range
  /// Repeated vertex index, exactly collinear corners (exact predicate), or a
  /// non-finite coordinate.
  std::size_t degenerate_triangles = 0;
  /// Same vertex set as an earlier triangle, in any order or orientation.
  std::size_t duplicate_triangles = 0;
  std::size_t edges = 0;
  std::size_t boundary_edges = 0;        // edges with exactly one triangle
  std::size_t non_manifold_edges = 0;    // edges with more than two triangles
  std::size_t non_manifold_vertices = 0; // pinches, see above
  /// Boundary curves. They are traced edge to edge; at a vertex, the two
  /// boundary edges that end the same fan of triangles continue each other,
  /// so at a pinch vertex the curves of the separate fans stay separate (two
  /// triangles sharing one vertex have two loops of three edges). A boundary
  /// edge whose fan ends at a non-manifold edge on the other side has no such
  /// partner; those are paired in increasing order of their far vertex index,
  /// and an odd one out ends an open chain. Open chains are counted here too
  /// and also in `open_boundary_chains`; they only occur next to non-manifold
  /// edges.
  std::size_t boundary_loops = 0;
  std::size_t open_boundary_chains = 0;
  /// Edges per boundary curve, largest first.
  std::vector<std::size_t> boundary_loop_lengths;
  std::size_t components = 0; // triangles connected through shared edges
  /// V - E + F over the combinatorial part (V = vertices it references).
  long long euler_characteristic = 0;
  /// True when every component can be oriented consistently. Only edges with
  /// exactly two triangles constrain orientation; a non-manifold edge joins
  /// components but imposes nothing (no orientation can satisfy three faces).
  bool orientable = true;
  std::size_t non_orientable_components = 0;
  /// Two-triangle edges traversed in the same direction by both triangles,
  /// with the orientation as given (0 for a consistently oriented mesh).
  std::size_t inconsistently_oriented_edges = 0;
  double used_vertex_fraction = 0; // referenced / vertices (0 without vertices)
  /// Median over valid triangles of their smallest angle (mean of the two
  /// middle values for an even count; 0 without triangles).
  double median_min_angle_deg = 0;
  double share_min_angle_below_10deg = 0; // share of valid triangles
};

MeshTopologyReport analyzeMesh(const std::vector<Eigen::Vector3d> &vertices,
                               const std::vector<Triangle> &triangles);

/// Smallest interior angle of a triangle in degrees; 0 when it is degenerate.
double minimumAngleDegrees(const Eigen::Vector3d &a, const Eigen::Vector3d &b,
                           const Eigen::Vector3d &c);

struct ReferenceOptions {
  /// Area-uniform random samples per mesh, on top of the deterministic ones
  /// (every referenced vertex, every triangle centroid, every edge midpoint).
  std::size_t surface_samples = 200000;
  std::uint32_t seed = 1; // fixed for reproducibility
  /// Vertex matching: 0 = the same coordinates, compared rounded to float
  /// (the precision of PCL's clouds, so that a reference read as doubles
  /// from text matches the float points meshed from it) unless rounding
  /// would merge two distinct positions of one mesh, and then bit for bit;
  /// else the largest distance (absolute units) to the nearest reference
  /// vertex.
  double position_tolerance = 0;
  /// true: mean, p95 and the F-scores come from the area-uniform samples only,
  /// so they do not depend on how finely either mesh is tessellated (vertices
  /// of an interpolating reconstruction sit on the reference and would pull
  /// the statistics towards 0). The max always uses every sample, which is
  /// what the deterministic samples are for. false: every statistic uses every
  /// sample. With surface_samples == 0 every sample is used either way.
  bool area_weighted_statistics = true;
};

/// Distances as fractions of the reference's bounding-box diagonal. When one
/// of the two meshes has no valid triangle all three are +infinity.
struct DistanceStats {
  double mean = 0, p95 = 0, max = 0;
};

struct ReferenceReport {
  /// Bounding-box diagonal of the reference vertices used by reference
  /// triangles (those taking part, see compareWithReference). When it is 0,
  /// distances are reported in absolute units and tau is 0.
  double reference_diagonal = 0;
  std::size_t reference_triangles = 0;
  /// Reference triangles whose three vertices, matched by position (see
  /// position_tolerance), form one of our triangles (any order or
  /// orientation). Reference vertices at the same coordinates count as one
  /// position.
  std::size_t recovered_reference_triangles = 0;
  std::size_t triangles = 0;              // ours
  std::size_t triangles_in_reference = 0; // ours that are reference triangles
  double recall = 0;                      // recovered / reference triangles (0 if none)
  double precision = 0;                   // in-reference / our triangles (0 if none)
  DistanceStats to_reference;             // our surface -> reference (max = one-sided Hausdorff)
  DistanceStats from_reference;           // reference -> our surface
  double fscore_0_1 = 0;                  // F-score at 0.1 % of the diagonal
  double fscore_0_5 = 0;                  // F-score at 0.5 % of the diagonal
};

/// Compares a mesh with a reference mesh: triangle recovery by vertex
/// position, and sampled surface distances in both directions through CGAL
/// AABB trees (exactly collinear triangles take part as their longest edge).
///  - p95 is the nearest-rank percentile; "within tau" means distance <= tau.
///  - F-score at tau: precision P = share of our samples within tau of the
///    reference, recall R = share of reference samples within tau of ours,
///    F = 2PR / (P + R), 0 when both are 0.
///  - Samples that coincide with the other mesh (a vertex at the same
///    position, or a point of a triangle the other mesh has with the same
///    three corners, positions matched as for recall, see
///    position_tolerance) get distance exactly 0 without a query, which
///    makes comparing nearly identical meshes cheap.
///  - Triangles with an index out of range or a non-finite corner are left
///    out of matching and distances, but still count in `triangles` and
///    `reference_triangles`, so they lower precision and recall.
///  - Deterministic for given options, whatever the number of cores used.
ReferenceReport compareWithReference(const std::vector<Eigen::Vector3d> &vertices,
                                     const std::vector<Triangle> &triangles,
                                     const std::vector<Eigen::Vector3d> &reference_vertices,
                                     const std::vector<Triangle> &reference_triangles,
                                     const ReferenceOptions &options = {});

} // namespace pcl_ms
