// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4's steps and the mesh structure they share (docs/algorithm.md
// section 4). In: a triangle list. Out: edge uses, boundary loops, manifold
// pairs (finish.cpp), filled holes (hole_filling.cpp), orientation and cuts
// (orientation.cpp), dropped triangles (bow_ties.cpp). Internal: not installed.
#pragma once

#include "edge_key.h"

#include <pcl_ms/finish.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace pcl_ms {
namespace detail {

/// One (edge, triangle) incidence, filed under the edge's lower vertex.
struct EdgeUse {
  VertexIndex high; // the edge's other vertex
  std::uint32_t triangle;
  bool operator<(const EdgeUse &other) const {
    return high < other.high || (high == other.high && triangle < other.triangle);
  }
};

/// Every (edge, triangle) incidence, by lower vertex (CSR), then by upper
/// vertex and triangle: 8 bytes an incidence, and only each vertex's few
/// edges are sorted.
struct EdgeUses {
  std::vector<std::uint32_t> offsets; // vertex v's uses are [offsets[v], offsets[v + 1])
  std::vector<EdgeUse> uses;
};

/// Calls work(i) for every i in [0, count), in parallel within the caller's
/// task arena. Each call must touch only its own outputs, so the result does
/// not depend on the number of threads.
template <typename Work> void forEachIndex(std::size_t count, const Work &work) {
  constexpr std::size_t grain = 1 << 12;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, grain),
                    [&](const tbb::blocked_range<std::size_t> &range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i)
                        work(i);
                    });
}

EdgeUses edgeUses(const std::vector<Triangle> &triangles);

/// Calls visit(key, first_use, count) for each distinct edge, in key order;
/// first_use indexes uses.uses.
template <typename Visit> void forEachEdge(const EdgeUses &uses, const Visit &visit) {
  const std::size_t vertex_count = uses.offsets.empty() ? 0 : uses.offsets.size() - 1;
  for (std::size_t low = 0; low < vertex_count; ++low) {
    const std::size_t end = uses.offsets[low + 1];
    for (std::size_t i = uses.offsets[low]; i < end;) {
      std::size_t j = i;
      while (j < end && uses.uses[j].high == uses.uses[i].high)
        ++j;
      visit(edgeKey(static_cast<VertexIndex>(low), uses.uses[i].high), i, j - i);
      i = j;
    }
  }
}

/// Two triangles sharing a manifold edge and the edge's end points (how much
/// the surface bends there is bendingAt(), computed where orientation needs it).
struct ManifoldPair {
  std::uint32_t first, second;
  VertexIndex a, b; // the shared edge
};

std::vector<ManifoldPair> manifoldPairs(const EdgeUses &uses);

/// Cyclic boundary loops (edges with one triangle), each starting at its
/// smallest vertex, in order of that vertex.
std::vector<std::vector<VertexIndex>> boundaryLoops(const EdgeUses &uses);

/// Closes loops of at most max_edges edges with triangles of the Delaunay
/// triangulation of the loop's vertices (minimum total P / C^2, no edge
/// that the mesh already has inside the hole, sides below the limit except
/// for a triangular hole), or any triangles when those cannot fill it
/// (docs/algorithm.md, "Finishing"). Only simple loops; with only_around,
/// only loops through a vertex marked there. Returns the holes closed.
std::size_t fillLoops(std::vector<Triangle> &triangles, std::vector<std::vector<VertexIndex>> loops,
                      const std::vector<Eigen::Vector3d> &points, int max_edges,
                      const SideLimit &limit, const std::vector<bool> *only_around);

/// orientComponents() given the mesh's manifold pairs.
std::vector<std::uint32_t> orientPairs(std::vector<Triangle> &triangles,
                                       const std::vector<ManifoldPair> &pairs,
                                       const std::vector<Eigen::Vector3d> &points,
                                       std::vector<std::uint32_t> &triangle_component,
                                       std::vector<bool> &component_orientable,
                                       const Eigen::Vector3d *viewpoint);

/// Drops the marked triangles; their corners are marked in touched.
void dropTriangles(std::vector<Triangle> &triangles, const std::vector<bool> &drop,
                   std::vector<bool> &touched);

} // namespace detail
} // namespace pcl_ms
