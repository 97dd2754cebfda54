// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4's steps and the mesh structure they share (docs/algorithm.md
// section 4). In: a triangle list. Out: boundary edges and loops, manifold
// neighbours (finish.cpp), filled holes (hole_filling.cpp), orientation and cuts
// (orientation.cpp), dropped triangles (bow_ties.cpp). Internal: not installed.
#pragma once

#include "edge_key.h"
#include "sort_unique.h"
#include "threads.h"

#include <pcl_ms/finish.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace pcl_ms {
namespace detail {

/// Calls work(i) for every i in [0, count), in parallel within the caller's
/// threads (threads.h). Each call must touch only its own outputs, so the
/// result does not depend on the number of threads.
template <typename Work> void forEachIndex(std::size_t count, const Work &work) {
  constexpr std::size_t grain = 1 << 12;
  parallelFor(tbb::blocked_range<std::size_t>(0, count, grain),
              [&](const tbb::blocked_range<std::size_t> &range) {
                for (std::size_t i = range.begin(); i != range.end(); ++i)
                  work(i);
              });
}

inline constexpr std::uint32_t no_neighbour = 0xffffffffu;

/// Where t's neighbour across `key` goes before its slots are packed (see
/// MeshEdges::neighbours): the edge's place among t's three edges in key
/// order.
inline std::size_t slotOf(const Triangle &t, EdgeKey key) {
  std::size_t below = 0;
  for (int k = 0; k < 3; ++k)
    below += edgeKey(t[k], t[(k + 1) % 3]) < key;
  return below;
}

/// Packs one triangle's three slots `own`: the neighbours first, in the
/// order they stand, then `none`.
template <typename Slot> void packSlotsOf(Slot *own, Slot none) {
  std::size_t kept = 0;
  for (std::size_t k = 0; k < 3; ++k)
    if (own[k] != none)
      own[kept++] = own[k];
  std::fill(own + kept, own + 3, none);
}

/// Packs each triangle's three slots (slots[3 t + k]) as packSlotsOf does.
template <typename Slot> void packSlots(std::vector<Slot> &slots, Slot none) {
  forEachIndex(slots.size() / 3, [&](std::size_t t) { packSlotsOf(&slots[3 * t], none); });
}

/// The edge that two neighbouring triangles share, as its key.
inline EdgeKey sharedEdge(const Triangle &first, const Triangle &second) {
  VertexIndex shared[2] = {0, 0};
  int found = 0;
  for (VertexIndex v : first)
    if ((v == second[0] || v == second[1] || v == second[2]) && found < 2)
      shared[found++] = v;
  return edgeKey(shared[0], shared[1]);
}

/// The corner (0-2) of triangle t that is neither end of its edge `key`.
inline int apexCorner(const Triangle &t, EdgeKey key) {
  for (int k = 0; k < 3; ++k)
    if (t[k] != lowVertex(key) && t[k] != highVertex(key))
      return k;
  return 0;
}

/// Whether triangle t, as stored, runs from a to b.
inline bool runsFromTo(const Triangle &t, VertexIndex a, VertexIndex b) {
  for (int k = 0; k < 3; ++k)
    if (t[k] == a && t[(k + 1) % 3] == b)
      return true;
  return false;
}

/// Whether neighbours t and u run their shared edge in opposite directions
/// (agree on their orientation).
inline bool consistentlyOriented(const Triangle &t, const Triangle &u) {
  for (int k = 0; k < 3; ++k)
    if (runsFromTo(u, t[(k + 1) % 3], t[k]))
      return true;
  return false;
}

/// What one scan of a triangle list's edges finds.
struct MeshEdges {
  /// Edges with one triangle, in key order.
  std::vector<EdgeKey> boundary;
  /// The triangle of each boundary edge.
  std::vector<std::uint32_t> boundary_triangle;
  /// Only when asked for: three slots per triangle holding the triangles
  /// across its manifold edges (edges with two triangles) in the order of
  /// those edges' keys, then no_neighbour. 12 bytes a triangle: at 10M
  /// points a list of pairs and each triangle's pairs took twice that.
  /// Its capacity matches the triangle list's, so that addFilling can grow
  /// it in place.
  std::vector<std::uint32_t> neighbours;
  /// Whether some edge has three triangles or more (no slots hold them).
  bool crowded = false;
};

// Twists are cut and the opened loops refilled at most this many times.
inline constexpr int max_untwist_rounds = 3;
// Loops opened by cutting twists are closed again up to this size.
inline constexpr int max_untwist_loop_edges = 16;

/// Scans every edge of `triangles` once. The (edge, triangle) incidences are
/// sorted a block of lower vertices at a time, at most `block_uses` per
/// block (16M: 128 MB), so that finishing a 20M-triangle surface never holds
/// them all. The result does not depend on the block size.
MeshEdges meshEdges(const std::vector<Triangle> &triangles, bool with_neighbours,
                    std::size_t block_uses = std::size_t(1) << 24);

/// Updates `edges` (with neighbours) of triangles[0, first_new) to cover
/// the whole list, when the triangles from first_new on only close boundary
/// edges and share new edges among themselves, as fillLoops' do: the same
/// as meshEdges(triangles, true), without a scan of the whole list.
void addFilling(MeshEdges &edges, const std::vector<Triangle> &triangles, std::size_t first_new);

/// Updates `edges` (with neighbours) of `triangles` to describe the list
/// without the triangles marked in `drop`, numbered as dropTriangles leaves
/// them: the same as meshEdges(kept, true) after a scan of the whole list,
/// at the cost of the dropped triangles and one pass over the slots. False,
/// with `edges` unchanged, where an edge has three triangles or more (such
/// edges have no slots to update).
bool dropFromMeshEdges(MeshEdges &edges, const std::vector<Triangle> &triangles,
                       const std::vector<bool> &drop);

/// Cyclic boundary loops traced along boundary edges (sorted), each starting
/// at its smallest vertex, in order of that vertex.
std::vector<std::vector<VertexIndex>> boundaryLoops(const std::vector<EdgeKey> &boundary);

/// Closes loops of at most max_edges edges with triangles of the Delaunay
/// triangulation of the loop's vertices (minimum total P / C^2, no edge
/// that the mesh already has inside the hole, sides below the limit except
/// for a triangular hole), or any triangles when those cannot fill it
/// (docs/algorithm.md, "Finishing"). Only simple loops; with only_around,
/// only loops through a vertex marked there. Appends the new triangles to
/// `added` (each of their edges is a boundary edge of `triangles` or a new
/// edge of two of them) and returns the holes closed. The three steps
/// below, in one process.
std::size_t fillLoops(const std::vector<Triangle> &triangles,
                      std::vector<std::vector<VertexIndex>> loops,
                      const std::vector<Eigen::Vector3d> &points, int max_edges,
                      const SideLimit &limit, const std::vector<bool> *only_around,
                      std::vector<Triangle> &added);

/// fillLoops' first step: the loops it may fill, in the order given: simple,
/// of 3 to max_edges edges and, unless `around` is empty, through a vertex
/// it marks.
std::vector<std::vector<VertexIndex>> fillableLoops(std::vector<std::vector<VertexIndex>> loops,
                                                    int max_edges,
                                                    const std::function<bool(VertexIndex)> &around);

/// fillLoops' second step: the edges (sorted, each once) and the triangles
/// (corners sorted; sorted, each once) of `triangles` whose corners all
/// satisfy on_loop, added to those given.
template <typename OnLoop>
void edgesAndTrianglesAmong(const std::vector<Triangle> &triangles, const OnLoop &on_loop,
                            std::vector<EdgeKey> &edges, std::vector<Triangle> &corners) {
  for (const Triangle &t : triangles) {
    const std::array<bool, 3> on = {on_loop(t[0]), on_loop(t[1]), on_loop(t[2])};
    for (int k = 0; k < 3; ++k)
      if (on[k] && on[(k + 1) % 3])
        edges.push_back(edgeKey(t[k], t[(k + 1) % 3]));
    if (on[0] && on[1] && on[2]) {
      Triangle sorted = t;
      std::sort(sorted.begin(), sorted.end());
      corners.push_back(sorted);
    }
  }
  detail::sortUnique(edges);
  detail::sortUnique(corners);
}

/// fillLoops' last step, given fillableLoops' loops and the mesh's edges
/// and triangles among their vertices.
std::size_t fillChosenLoops(const std::vector<std::vector<VertexIndex>> &loops,
                            const std::vector<Eigen::Vector3d> &points, const SideLimit &limit,
                            std::vector<EdgeKey> mesh_edges, const std::vector<Triangle> &existing,
                            std::vector<Triangle> &added);

/// orientComponents() given the mesh's manifold neighbours (MeshEdges).
std::vector<std::uint32_t> orientAlongNeighbours(std::vector<Triangle> &triangles,
                                                 const std::vector<std::uint32_t> &neighbours,
                                                 const std::vector<Eigen::Vector3d> &points,
                                                 std::vector<std::uint32_t> &triangle_component,
                                                 std::vector<bool> &component_orientable,
                                                 const Eigen::Vector3d *viewpoint);

/// Drops the marked triangles; their corners are marked in touched. With
/// `edges` (with neighbours, of `triangles`), keeps them up to date.
void dropTriangles(std::vector<Triangle> &triangles, const std::vector<bool> &drop,
                   std::vector<bool> &touched, MeshEdges *edges = nullptr);

/// One vertex's share of a round of splitBowTies(): the triangles [first,
/// last) around v (ascending; numbers into `triangles`) grouped into fans
/// joined by edges at v, and those of every fan but the one to keep
/// (fan_choice.h) appended to `drop`, except those is_fixed (if given) marks.
void dropBowTieFans(VertexIndex v, const std::uint32_t *first, const std::uint32_t *last,
                    const std::vector<Triangle> &triangles,
                    const std::function<bool(std::uint32_t)> &is_fixed,
                    std::vector<std::uint32_t> &drop);

/// splitBowTies() keeping `edges` (with neighbours) up to date.
std::size_t splitBowTies(std::vector<Triangle> &triangles, std::size_t vertex_count,
                         std::vector<bool> &touched, const std::vector<Triangle> *fixed,
                         MeshEdges *edges);

} // namespace detail
} // namespace pcl_ms
