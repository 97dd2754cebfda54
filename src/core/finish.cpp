// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4, finishing (docs/algorithm.md section 4). In: the greedy's
// triangles and the points. Out: a FinishedSurface: small holes filled, folds
// cut, bow-ties split, components oriented, boundary loops traced. The steps
// are in hole_filling.cpp, orientation.cpp, bow_ties.cpp; this file drives them.
#include "finish_steps.h"
#include "sort_unique.h"

#include <algorithm>
#include <array>
#include <utility>

namespace pcl_ms {
namespace detail {

namespace {

/// One (edge, triangle) incidence, filed under the edge's lower vertex.
struct EdgeUse {
  VertexIndex high; // the edge's other vertex
  std::uint32_t triangle;
  bool operator<(const EdgeUse &other) const {
    return high < other.high || (high == other.high && triangle < other.triangle);
  }
};

/// Replaces the boundary edges of `edges` by those that `leaves(e)` keeps,
/// with `opened` (key, triangle; sorted) merged in, in key order; every
/// triangle number passes through `number`.
template <typename Leaves, typename Number>
void mergeBoundary(MeshEdges &edges, const std::vector<std::pair<EdgeKey, std::uint32_t>> &opened,
                   const Leaves &leaves, const Number &number) {
  std::vector<EdgeKey> boundary;
  std::vector<std::uint32_t> boundary_triangle;
  boundary.reserve(edges.boundary.size() + opened.size());
  boundary_triangle.reserve(boundary.capacity());
  auto next_opened = opened.begin();
  for (std::size_t e = 0; e <= edges.boundary.size(); ++e) {
    const bool last = e == edges.boundary.size();
    for (; next_opened != opened.end() && (last || next_opened->first < edges.boundary[e]);
         ++next_opened) {
      boundary.push_back(next_opened->first);
      boundary_triangle.push_back(number(next_opened->second));
    }
    if (!last && !leaves(e)) {
      boundary.push_back(edges.boundary[e]);
      boundary_triangle.push_back(number(edges.boundary_triangle[e]));
    }
  }
  edges.boundary = std::move(boundary);
  edges.boundary_triangle = std::move(boundary_triangle);
}

} // namespace

MeshEdges meshEdges(const std::vector<Triangle> &triangles, bool with_neighbours,
                    std::size_t block_uses) {
  // Every (edge, triangle) incidence, filed under the edge's lower vertex and
  // sorted there; each distinct edge then gives a boundary edge or a pair of
  // neighbours. A 20M-triangle surface has 60M incidences: holding them all
  // beside the triangles, points and neighbours set the peak of a whole MPI
  // run's rank 0 (docs/algorithm.md, "Across processes"), so they are filed
  // for a block of lower vertices at a time. Threads file them in any order
  // and the sort settles it, so the result does not depend on the threads.
  const std::size_t count = triangles.size();
  const VertexIndex vertex_count = parallelReduce(
      tbb::blocked_range<std::size_t>(0, count, 1 << 12), VertexIndex{0},
      [&](const tbb::blocked_range<std::size_t> &range, VertexIndex highest) {
        for (std::size_t t = range.begin(); t != range.end(); ++t)
          for (VertexIndex v : triangles[t])
            highest = std::max(highest, v + 1);
        return highest;
      },
      [](VertexIndex a, VertexIndex b) { return std::max(a, b); });
  // offsets[v]: the incidences filed under vertices below v.
  std::vector<std::uint64_t> offsets(static_cast<std::size_t>(vertex_count) + 1, 0);
  forEachIndex(count, [&](std::size_t t) {
    for (int k = 0; k < 3; ++k)
      countUp(offsets[lowVertex(edgeKey(triangles[t][k], triangles[t][(k + 1) % 3])) + 1]);
  });
  for (std::size_t v = 0; v < vertex_count; ++v)
    offsets[v + 1] += offsets[v];

  MeshEdges edges;
  if (with_neighbours) {
    edges.neighbours.reserve(3 * triangles.capacity());
    edges.neighbours.assign(3 * count, no_neighbour);
  }
  // A block's lower vertices in parts, each part's boundary edges found apart.
  constexpr std::size_t parts_per_block = 64;
  struct Boundary {
    std::vector<EdgeKey> keys;
    std::vector<std::uint32_t> triangles;
    bool crowded = false; // an edge with three triangles or more
  };
  std::vector<Boundary> parts(parts_per_block);
  std::vector<EdgeUse> uses;
  uses.reserve(std::min<std::uint64_t>(block_uses, offsets[vertex_count])); // no regrowth
  std::vector<std::uint32_t> cursor;
  for (VertexIndex begin = 0; begin < vertex_count;) {
    VertexIndex end = begin + 1;
    while (end < vertex_count && offsets[end + 1] - offsets[begin] <= block_uses)
      ++end;
    const std::uint64_t base = offsets[begin];
    uses.resize(offsets[end] - base);
    cursor.resize(end - begin);
    for (VertexIndex v = begin; v < end; ++v)
      cursor[v - begin] = static_cast<std::uint32_t>(offsets[v] - base);
    forEachIndex(count, [&](std::size_t t) {
      for (int k = 0; k < 3; ++k) {
        const EdgeKey key = edgeKey(triangles[t][k], triangles[t][(k + 1) % 3]);
        const VertexIndex low = lowVertex(key);
        if (low >= begin && low < end)
          uses[countUp(cursor[low - begin])] = {highVertex(key), static_cast<std::uint32_t>(t)};
      }
    });
    const std::size_t block_vertices = end - begin;
    forEachIndex(block_vertices, [&](std::size_t i) {
      std::sort(uses.begin() + static_cast<std::ptrdiff_t>(offsets[begin + i] - base),
                uses.begin() + static_cast<std::ptrdiff_t>(offsets[begin + i + 1] - base));
    });
    parallelFor(std::size_t(0), parts_per_block, [&](std::size_t part) {
      Boundary &boundary = parts[part];
      boundary.keys.clear();
      boundary.triangles.clear();
      boundary.crowded = false;
      const VertexIndex first_low = static_cast<VertexIndex>(begin + block_vertices * part /
                                                                         parts_per_block),
                        last_low = static_cast<VertexIndex>(begin + block_vertices * (part + 1) /
                                                                        parts_per_block);
      for (VertexIndex low = first_low; low < last_low; ++low) {
        const std::size_t last = offsets[low + 1] - base;
        for (std::size_t i = offsets[low] - base; i < last;) {
          std::size_t j = i;
          while (j < last && uses[j].high == uses[i].high)
            ++j;
          const EdgeKey key = edgeKey(low, uses[i].high);
          if (j - i == 1) {
            boundary.keys.push_back(key);
            boundary.triangles.push_back(uses[i].triangle);
          } else if (j - i == 2) {
            if (with_neighbours) {
              const std::uint32_t t = uses[i].triangle, u = uses[i + 1].triangle;
              edges.neighbours[3 * std::size_t{t} + slotOf(triangles[t], key)] = u;
              edges.neighbours[3 * std::size_t{u} + slotOf(triangles[u], key)] = t;
            }
          } else {
            boundary.crowded = true;
          }
          i = j;
        }
      }
    });
    for (const Boundary &boundary : parts) {
      edges.crowded = edges.crowded || boundary.crowded;
      edges.boundary.insert(edges.boundary.end(), boundary.keys.begin(), boundary.keys.end());
      edges.boundary_triangle.insert(edges.boundary_triangle.end(), boundary.triangles.begin(),
                                     boundary.triangles.end());
    }
    begin = end;
  }
  // Each triangle's neighbours first, still in the order of the edges' keys.
  if (with_neighbours)
    packSlots(edges.neighbours, no_neighbour);
  return edges;
}

void addFilling(MeshEdges &edges, const std::vector<Triangle> &triangles, std::size_t first_new) {
  struct Use {
    EdgeKey key;
    std::uint32_t triangle;
    bool operator<(const Use &other) const {
      return key < other.key || (key == other.key && triangle < other.triangle);
    }
  };
  std::vector<Use> uses;
  for (std::size_t t = first_new; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      uses.push_back(
          {edgeKey(triangles[t][k], triangles[t][(k + 1) % 3]), static_cast<std::uint32_t>(t)});
  std::sort(uses.begin(), uses.end());
  edges.neighbours.resize(3 * triangles.size(), no_neighbour);
  std::vector<std::uint32_t> relinked;
  auto link = [&](std::uint32_t t, std::uint32_t u) {
    std::uint32_t *slot = &edges.neighbours[3 * std::size_t{t}];
    while (*slot != no_neighbour)
      ++slot;
    *slot = u;
    relinked.push_back(t);
  };
  std::vector<bool> closed(edges.boundary.size(), false);
  std::vector<std::pair<EdgeKey, std::uint32_t>> opened;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key)
      ++j;
    const auto at = std::lower_bound(edges.boundary.begin(), edges.boundary.end(), uses[i].key);
    const bool was_boundary = at != edges.boundary.end() && *at == uses[i].key;
    const std::size_t count = j - i + (was_boundary ? 1 : 0);
    std::uint32_t first = uses[i].triangle;
    if (was_boundary) {
      const std::size_t index = static_cast<std::size_t>(at - edges.boundary.begin());
      closed[index] = true;
      first = edges.boundary_triangle[index];
    }
    if (count == 2) {
      link(first, uses[j - 1].triangle);
      link(uses[j - 1].triangle, first);
    } else if (count == 1) {
      opened.emplace_back(uses[i].key, uses[i].triangle);
    } else {
      edges.crowded = true; // three or more: not manifold, no neighbours
    }
    i = j;
  }
  // Each relinked triangle's slots back in the order of the edges' keys.
  detail::sortUnique(relinked);
  for (std::uint32_t t : relinked) {
    std::uint32_t *slots = &edges.neighbours[3 * std::size_t{t}];
    std::array<std::pair<EdgeKey, std::uint32_t>, 3> by_key;
    std::size_t count = 0;
    for (; count < 3 && slots[count] != no_neighbour; ++count) {
      by_key[count] = {sharedEdge(triangles[t], triangles[slots[count]]), slots[count]};
    }
    std::sort(by_key.begin(), by_key.begin() + static_cast<std::ptrdiff_t>(count));
    for (std::size_t k = 0; k < count; ++k)
      slots[k] = by_key[k].second;
  }
  // The boundary without the closed edges, with the opened ones, in key order.
  std::sort(opened.begin(), opened.end());
  mergeBoundary(
      edges, opened, [&](std::size_t e) { return closed[e]; }, [](std::uint32_t t) { return t; });
}

bool dropFromMeshEdges(MeshEdges &edges, const std::vector<Triangle> &triangles,
                       const std::vector<bool> &drop) {
  if (edges.crowded)
    return false;
  const std::size_t count = triangles.size();
  std::vector<std::uint32_t> dropped;
  for (std::uint32_t t = 0; t < count; ++t)
    if (drop[t])
      dropped.push_back(t);
  if (dropped.empty())
    return true;

  // A kept neighbour's shared edge opens; a dropped triangle's own boundary
  // edges go. The kept neighbour's slots stay in key order without it.
  std::vector<std::pair<EdgeKey, std::uint32_t>> opened;
  std::vector<EdgeKey> gone;
  for (std::uint32_t t : dropped) {
    std::array<EdgeKey, 3> own;
    for (int k = 0; k < 3; ++k)
      own[static_cast<std::size_t>(k)] = edgeKey(triangles[t][k], triangles[t][(k + 1) % 3]);
    std::array<bool, 3> shared = {false, false, false};
    const std::uint32_t *slots = &edges.neighbours[3 * std::size_t{t}];
    for (std::size_t k = 0; k < 3 && slots[k] != no_neighbour; ++k) {
      const std::uint32_t u = slots[k];
      const EdgeKey key = sharedEdge(triangles[t], triangles[u]);
      for (std::size_t i = 0; i < 3; ++i)
        shared[i] = shared[i] || own[i] == key;
      if (drop[u])
        continue; // the edge goes with both
      opened.emplace_back(key, u);
      std::uint32_t *at = &edges.neighbours[3 * std::size_t{u}];
      std::uint32_t *end = std::remove(at, at + 3, t);
      std::fill(end, at + 3, no_neighbour);
    }
    for (std::size_t i = 0; i < 3; ++i)
      if (!shared[i])
        gone.push_back(own[i]);
  }

  // New numbers: each kept triangle moves down by the dropped ones before it.
  std::vector<std::uint32_t> renumbered(count);
  for (std::uint32_t t = 0, next = 0; t < count; ++t)
    renumbered[t] = drop[t] ? no_neighbour : next++;
  forEachIndex(count, [&](std::size_t t) {
    if (drop[t])
      return;
    for (std::size_t k = 3 * t; k < 3 * t + 3 && edges.neighbours[k] != no_neighbour; ++k)
      edges.neighbours[k] = renumbered[edges.neighbours[k]];
  });
  // The dropped triangles' slots leave the list: the runs between them move down.
  auto write = edges.neighbours.begin();
  std::size_t run_begin = 0;
  for (std::size_t i = 0; i <= dropped.size(); ++i) {
    const std::size_t run_end = i < dropped.size() ? dropped[i] : count;
    write = std::copy(edges.neighbours.begin() + static_cast<std::ptrdiff_t>(3 * run_begin),
                      edges.neighbours.begin() + static_cast<std::ptrdiff_t>(3 * run_end), write);
    run_begin = run_end + 1;
  }
  edges.neighbours.resize(3 * (count - dropped.size()));

  // The boundary without the gone edges, with the opened ones, in key order.
  std::sort(gone.begin(), gone.end());
  std::sort(opened.begin(), opened.end());
  mergeBoundary(
      edges, opened,
      [&](std::size_t e) {
        return std::binary_search(gone.begin(), gone.end(), edges.boundary[e]);
      },
      [&](std::uint32_t t) { return renumbered[t]; });
  return true;
}

std::vector<std::vector<VertexIndex>> boundaryLoops(const std::vector<EdgeKey> &boundary) {
  // Boundary edges in both directions, sorted: a CSR of boundary neighbours.
  struct HalfEdge {
    VertexIndex from, to;
    std::uint32_t edge;
    bool operator<(const HalfEdge &other) const {
      return from < other.from || (from == other.from && to < other.to);
    }
  };
  std::vector<HalfEdge> half_edges;
  half_edges.reserve(2 * boundary.size());
  for (std::uint32_t e = 0; e < boundary.size(); ++e) {
    half_edges.push_back({lowVertex(boundary[e]), highVertex(boundary[e]), e});
    half_edges.push_back({highVertex(boundary[e]), lowVertex(boundary[e]), e});
  }
  std::sort(half_edges.begin(), half_edges.end());
  std::vector<bool> used(boundary.size(), false);
  auto nextFrom = [&](VertexIndex v) -> const HalfEdge * {
    HalfEdge probe{v, 0, 0};
    for (auto it = std::lower_bound(half_edges.begin(), half_edges.end(), probe);
         it != half_edges.end() && it->from == v; ++it)
      if (!used[it->edge])
        return &*it;
    return nullptr;
  };
  std::vector<std::vector<VertexIndex>> loops;
  // Half-edges are sorted by start vertex, so each loop is met first at its
  // smallest vertex.
  for (const HalfEdge &start : half_edges) {
    if (used[start.edge] || start.from > start.to)
      continue;
    std::vector<VertexIndex> loop = {start.from};
    used[start.edge] = true;
    VertexIndex current = start.to;
    while (current != start.from) {
      loop.push_back(current);
      const HalfEdge *next = nextFrom(current);
      if (!next)
        break;
      used[next->edge] = true;
      current = next->to;
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

} // namespace detail

namespace {

// Room kept for hole fillings: a 1M-point surface (2M triangles) takes
// about 500 triangles in 100 holes.
constexpr std::size_t fill_room_divisor = 256;
constexpr std::size_t min_fill_room = 64;

} // namespace

std::vector<std::vector<VertexIndex>> traceBoundaryLoops(const std::vector<Triangle> &triangles) {
  return detail::boundaryLoops(detail::meshEdges(triangles, false).boundary);
}

FinishedSurface finishSurface(std::vector<Triangle> triangles,
                              const std::vector<Eigen::Vector3d> &points, int fill_holes_max_edges,
                              const SideLimit &limit, const std::vector<Triangle> *fixed_triangles,
                              const Eigen::Vector3d *viewpoint) {
  FinishedSurface surface;
  // The user's fixed triangles survive the twist repair: no triangle at their
  // corners is cut, and the bow-tie split keeps them.
  std::vector<Triangle> fixed;
  std::vector<bool> anchored;
  if (fixed_triangles) {
    anchored.assign(points.size(), false);
    for (Triangle triangle : *fixed_triangles) {
      std::sort(triangle.begin(), triangle.end());
      fixed.push_back(triangle);
      for (VertexIndex v : triangle)
        anchored[v] = true;
    }
    std::sort(fixed.begin(), fixed.end());
  }
  // Room for the fillings, so that they join the list while its neighbours
  // are held: moving a 20M-triangle list then would add 240 MB to the peak.
  triangles.reserve(triangles.size() + triangles.size() / fill_room_divisor + min_fill_room);
  // One scan of the edges; removals and fillings update it from then on.
  detail::MeshEdges edges = detail::meshEdges(triangles, true);
  auto fillThenOrient = [&](int max_edges, const std::vector<bool> *only_around) {
    surface.boundary_loops = detail::boundaryLoops(edges.boundary);
    std::vector<Triangle> filling;
    const std::size_t filled = detail::fillLoops(triangles, surface.boundary_loops, points,
                                                 max_edges, limit, only_around, filling);
    if (filled > 0) {
      const std::size_t first_new = triangles.size();
      if (triangles.capacity() - first_new >= filling.size()) {
        triangles.insert(triangles.end(), filling.begin(), filling.end());
        detail::addFilling(edges, triangles, first_new);
      } else {
        // Out of room: the list moves, without the neighbours (as large)
        // held meanwhile, and they are found again.
        edges = detail::MeshEdges();
        triangles.reserve(first_new + filling.size() + min_fill_room);
        triangles.insert(triangles.end(), filling.begin(), filling.end());
        edges = detail::meshEdges(triangles, true);
      }
      surface.boundary_loops = detail::boundaryLoops(edges.boundary);
    }
    surface.holes_filled += filled;
    return detail::orientAlongNeighbours(triangles, edges.neighbours, points,
                                         surface.triangle_component, surface.component_orientable,
                                         viewpoint);
  };
  std::vector<std::uint32_t> to_cut = fillThenOrient(fill_holes_max_edges, nullptr);
  for (int round = 0; round < detail::max_untwist_rounds && !to_cut.empty(); ++round) {
    // Only the triangles at the inconsistent edges go, never whole fans:
    // cutting the most crumpled corner's fan at sharp folds split sparse
    // scans and the camel head apart (car6: 80 pieces instead of 52).
    std::vector<bool> drop(triangles.size(), false);
    for (std::uint32_t t : to_cut)
      drop[t] = anchored.empty() || std::none_of(triangles[t].begin(), triangles[t].end(),
                                                 [&](VertexIndex v) { return anchored[v]; });
    const std::size_t before = triangles.size();
    std::vector<bool> touched(points.size(), false);
    detail::dropTriangles(triangles, drop, touched, &edges);
    detail::splitBowTies(triangles, points.size(), touched, fixed_triangles ? &fixed : nullptr,
                         &edges);
    surface.twist_triangles_removed += before - triangles.size();
    // The loops that removal opened are ours to close, whatever the user's limit.
    to_cut = fillThenOrient(detail::max_untwist_loop_edges, &touched);
  }
  surface.triangles = std::move(triangles);
  return surface;
}

} // namespace pcl_ms
