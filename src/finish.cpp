// SPDX-License-Identifier: GPL-3.0-or-later
#include <pcl_ms/costs.h>
#include <pcl_ms/finish.h>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <limits>
#include <queue>
#include <set>

namespace pcl_ms {
namespace {

using EdgeKey = std::uint64_t;

EdgeKey edgeKey(VertexIndex a, VertexIndex b) {
  if (a > b)
    std::swap(a, b);
  return (static_cast<EdgeKey>(a) << 32) | b;
}

struct EdgeUse {
  EdgeKey key;
  std::uint32_t triangle;
  bool operator<(const EdgeUse &other) const {
    return key < other.key || (key == other.key && triangle < other.triangle);
  }
};

/// Every (edge, triangle) incidence, sorted by edge then triangle.
std::vector<EdgeUse> edgeUses(const std::vector<Triangle> &triangles) {
  std::vector<EdgeUse> uses;
  uses.reserve(3 * triangles.size());
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      uses.push_back({edgeKey(triangles[t][k], triangles[t][(k + 1) % 3]), t});
  std::sort(uses.begin(), uses.end());
  return uses;
}

/// Calls visit(key, first_use, count) for each distinct edge.
template <typename Visit> void forEachEdge(const std::vector<EdgeUse> &uses, const Visit &visit) {
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key)
      ++j;
    visit(uses[i].key, i, j - i);
    i = j;
  }
}

VertexIndex lowVertex(EdgeKey key) { return static_cast<VertexIndex>(key >> 32); }
VertexIndex highVertex(EdgeKey key) { return static_cast<VertexIndex>(key & 0xffffffffu); }

/// Whether triangle t, as stored, runs from a to b.
bool runsFromTo(const Triangle &t, VertexIndex a, VertexIndex b) {
  for (int k = 0; k < 3; ++k)
    if (t[k] == a && t[(k + 1) % 3] == b)
      return true;
  return false;
}

/// Minimum-cost triangulation of one boundary loop, or nothing.
std::vector<Triangle> triangulateLoop(const std::vector<VertexIndex> &loop,
                                      const std::vector<Eigen::Vector3d> &points,
                                      const std::vector<EdgeKey> &mesh_edges, double max_side) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using VertexBase = CGAL::Triangulation_vertex_base_with_info_3<std::size_t, Kernel>;
  using DataStructure = CGAL::Triangulation_data_structure_3<VertexBase>;
  using Delaunay = CGAL::Delaunay_triangulation_3<Kernel, DataStructure>;

  const std::size_t m = loop.size();
  std::vector<std::pair<Kernel::Point_3, std::size_t>> input;
  for (std::size_t i = 0; i < m; ++i) {
    const Eigen::Vector3d &p = points[loop[i]];
    input.emplace_back(Kernel::Point_3(p.x(), p.y(), p.z()), i);
  }
  const Delaunay delaunay(input.begin(), input.end());
  if (delaunay.dimension() < 2)
    return {};
  std::set<std::array<std::size_t, 3>> allowed;
  for (auto facet = delaunay.finite_facets_begin(); facet != delaunay.finite_facets_end();
       ++facet) {
    std::array<std::size_t, 3> corners;
    for (int k = 0; k < 3; ++k)
      corners[k] = facet->first->vertex((facet->second + 1 + k) & 3)->info();
    if (delaunay.dimension() == 2)
      corners = {facet->first->vertex(0)->info(), facet->first->vertex(1)->info(),
                 facet->first->vertex(2)->info()};
    std::sort(corners.begin(), corners.end());
    allowed.insert(corners);
  }
  auto isMeshEdge = [&](std::size_t i, std::size_t j) {
    return std::binary_search(mesh_edges.begin(), mesh_edges.end(), edgeKey(loop[i], loop[j]));
  };
  // Classic polygon DP: best[i][j] triangulates loop[i..j] above chord (i, j).
  const double infinity = std::numeric_limits<double>::infinity();
  std::vector<std::vector<double>> best(m, std::vector<double>(m, infinity));
  std::vector<std::vector<std::size_t>> split(m, std::vector<std::size_t>(m, 0));
  for (std::size_t i = 0; i + 1 < m; ++i)
    best[i][i + 1] = 0;
  for (std::size_t span = 2; span < m; ++span)
    for (std::size_t i = 0; i + span < m; ++i) {
      const std::size_t j = i + span;
      // A chord that is not a loop edge must be new, or the hole's filling
      // would put a third triangle on an existing edge.
      if (!(i == 0 && j == m - 1) && isMeshEdge(i, j))
        continue;
      for (std::size_t k = i + 1; k < j; ++k) {
        if (best[i][k] == infinity || best[k][j] == infinity || !allowed.count({i, k, j}))
          continue;
        const TriangleShape shape =
            triangleShape(points[loop[i]], points[loop[k]], points[loop[j]]);
        // A triangular hole takes its one triangle whatever its size; larger
        // loops keep the greedy's size limit, or fillings would reach across
        // concave spots.
        if (shape.compactness <= 0 || (m > 3 && shape.longest_side >= max_side))
          continue;
        const double cost =
            best[i][k] + best[k][j] + shape.perimeter / (shape.compactness * shape.compactness);
        if (cost < best[i][j]) {
          best[i][j] = cost;
          split[i][j] = k;
        }
      }
    }
  if (best[0][m - 1] == infinity)
    return {};
  std::vector<Triangle> filling;
  std::vector<std::pair<std::size_t, std::size_t>> stack = {{0, m - 1}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    if (j < i + 2)
      continue;
    const std::size_t k = split[i][j];
    filling.push_back({loop[i], loop[k], loop[j]});
    stack.push_back({i, k});
    stack.push_back({k, j});
  }
  return filling;
}

} // namespace

std::vector<std::vector<VertexIndex>> traceBoundaryLoops(const std::vector<Triangle> &triangles) {
  const std::vector<EdgeUse> uses = edgeUses(triangles);
  // Boundary edges in both directions, sorted: a CSR of boundary neighbours.
  struct HalfEdge {
    VertexIndex from, to;
    std::uint32_t edge;
    bool operator<(const HalfEdge &other) const {
      return from < other.from || (from == other.from && to < other.to);
    }
  };
  std::vector<HalfEdge> half_edges;
  std::uint32_t boundary_edges = 0;
  forEachEdge(uses, [&](EdgeKey key, std::size_t, std::size_t count) {
    if (count != 1)
      return;
    half_edges.push_back({lowVertex(key), highVertex(key), boundary_edges});
    half_edges.push_back({highVertex(key), lowVertex(key), boundary_edges});
    ++boundary_edges;
  });
  std::sort(half_edges.begin(), half_edges.end());
  std::vector<bool> used(boundary_edges, false);
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

std::size_t fillHoles(std::vector<Triangle> &triangles, const std::vector<Eigen::Vector3d> &points,
                      int max_edges, double max_side) {
  if (max_edges < 3)
    return 0;
  const auto loops = traceBoundaryLoops(triangles);
  const bool any_small_loop = std::any_of(loops.begin(), loops.end(), [&](const auto &loop) {
    return loop.size() <= static_cast<std::size_t>(max_edges);
  });
  if (!any_small_loop)
    return 0;
  std::vector<EdgeKey> mesh_edges;
  for (const Triangle &t : triangles)
    for (int k = 0; k < 3; ++k)
      mesh_edges.push_back(edgeKey(t[k], t[(k + 1) % 3]));
  std::sort(mesh_edges.begin(), mesh_edges.end());
  mesh_edges.erase(std::unique(mesh_edges.begin(), mesh_edges.end()), mesh_edges.end());
  // Existing triangles matter only where all three corners are on a loop.
  std::vector<bool> on_small_loop(points.size(), false);
  for (const auto &loop : loops)
    if (loop.size() <= static_cast<std::size_t>(max_edges))
      for (VertexIndex v : loop)
        on_small_loop[v] = true;
  std::set<std::array<VertexIndex, 3>> existing;
  for (Triangle t : triangles)
    if (on_small_loop[t[0]] && on_small_loop[t[1]] && on_small_loop[t[2]]) {
      std::sort(t.begin(), t.end());
      existing.insert(t);
    }

  std::size_t filled = 0;
  for (const auto &loop : loops) {
    if (loop.size() < 3 || loop.size() > static_cast<std::size_t>(max_edges))
      continue;
    std::vector<Triangle> filling = triangulateLoop(loop, points, mesh_edges, max_side);
    bool duplicates_existing = false;
    for (Triangle t : filling) {
      std::sort(t.begin(), t.end());
      duplicates_existing |= existing.count(t) > 0;
    }
    if (filling.empty() || duplicates_existing)
      continue;
    for (const Triangle &t : filling)
      for (int k = 0; k < 3; ++k) {
        const EdgeKey key = edgeKey(t[k], t[(k + 1) % 3]);
        mesh_edges.insert(std::lower_bound(mesh_edges.begin(), mesh_edges.end(), key), key);
      }
    triangles.insert(triangles.end(), filling.begin(), filling.end());
    ++filled;
  }
  return filled;
}

void orientComponents(std::vector<Triangle> &triangles, const std::vector<Eigen::Vector3d> &points,
                      std::vector<std::uint32_t> &triangle_component,
                      std::vector<bool> &component_orientable) {
  const std::uint32_t unvisited = std::numeric_limits<std::uint32_t>::max();
  const std::vector<EdgeUse> uses = edgeUses(triangles);
  // Neighbours across manifold edges (exactly two triangles), as a CSR.
  std::vector<std::uint32_t> offsets(triangles.size() + 1, 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  forEachEdge(uses, [&](EdgeKey, std::size_t first, std::size_t count) {
    if (count == 2)
      pairs.emplace_back(uses[first].triangle, uses[first + 1].triangle);
  });
  for (const auto &[a, b] : pairs) {
    ++offsets[a + 1];
    ++offsets[b + 1];
  }
  for (std::size_t t = 0; t < triangles.size(); ++t)
    offsets[t + 1] += offsets[t];
  std::vector<std::uint32_t> neighbours(offsets.back());
  {
    std::vector<std::uint32_t> cursor(offsets.begin(), offsets.end() - 1);
    for (const auto &[a, b] : pairs) {
      neighbours[cursor[a]++] = b;
      neighbours[cursor[b]++] = a;
    }
  }

  triangle_component.assign(triangles.size(), unvisited);
  component_orientable.clear();
  std::vector<std::uint32_t> members;
  for (std::uint32_t seed = 0; seed < triangles.size(); ++seed) {
    if (triangle_component[seed] != unvisited)
      continue;
    const std::uint32_t component = static_cast<std::uint32_t>(component_orientable.size());
    bool orientable = true;
    members.clear();
    std::queue<std::uint32_t> frontier;
    frontier.push(seed);
    triangle_component[seed] = component;
    while (!frontier.empty()) {
      const std::uint32_t t = frontier.front();
      frontier.pop();
      members.push_back(t);
      for (std::uint32_t i = offsets[t]; i < offsets[t + 1]; ++i) {
        const std::uint32_t u = neighbours[i];
        // The shared edge must run in opposite directions in t and u.
        VertexIndex a = 0, b = 0;
        for (int k = 0; k < 3; ++k) {
          const VertexIndex from = triangles[t][k], to = triangles[t][(k + 1) % 3];
          if (std::count(triangles[u].begin(), triangles[u].end(), from) &&
              std::count(triangles[u].begin(), triangles[u].end(), to)) {
            a = from;
            b = to;
          }
        }
        const bool consistent = runsFromTo(triangles[u], b, a);
        if (triangle_component[u] == unvisited) {
          if (!consistent)
            std::swap(triangles[u][1], triangles[u][2]);
          triangle_component[u] = component;
          frontier.push(u);
        } else if (!consistent) {
          orientable = false;
        }
      }
    }
    if (orientable) {
      // Outward for closed surfaces; a fixed, reproducible choice otherwise.
      double signed_volume = 0;
      for (std::uint32_t t : members)
        signed_volume +=
            points[triangles[t][0]].dot(points[triangles[t][1]].cross(points[triangles[t][2]]));
      if (signed_volume < 0)
        for (std::uint32_t t : members)
          std::swap(triangles[t][1], triangles[t][2]);
    }
    component_orientable.push_back(orientable);
  }
}

FinishedSurface finishSurface(std::vector<Triangle> triangles,
                              const std::vector<Eigen::Vector3d> &points, int fill_holes_max_edges,
                              double max_side) {
  FinishedSurface surface;
  surface.holes_filled = fillHoles(triangles, points, fill_holes_max_edges, max_side);
  orientComponents(triangles, points, surface.triangle_component, surface.component_orientable);
  surface.boundary_loops = traceBoundaryLoops(triangles);
  surface.triangles = std::move(triangles);
  return surface;
}

} // namespace pcl_ms
