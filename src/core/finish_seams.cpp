// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4a, the seam triangles join the finished surface (docs/algorithm.md
// section 4a). In: the finished 2-manifold surface, the seam pass's
// triangles and the greedy's. Out: the surface with the seam triangles, its
// manifold sheets as components, and the edges holding three or more.
#include <pcl_ms/finish.h>

#include <algorithm>
#include <limits>
#include <map>
#include <numeric>
#include <queue>
#include <set>
#include <utility>

namespace pcl_ms {

std::vector<std::array<VertexIndex, 2>> attachSeamTriangles(FinishedSurface &surface,
                                                            const std::vector<Triangle> &seam,
                                                            const std::vector<Triangle> &greedy) {
  std::vector<Triangle> &triangles = surface.triangles;
  std::size_t finished = triangles.size();
  auto key = [](VertexIndex a, VertexIndex b) {
    return std::make_pair(std::min(a, b), std::max(a, b));
  };
  {
    // A triangle the finish added (a hole filled) on an edge of a seam
    // triangle closed the gap that setting the seam triangles apart left:
    // it goes, and the seam triangle takes its place.
    std::set<Triangle> from_greedy;
    for (Triangle triangle : greedy) {
      std::sort(triangle.begin(), triangle.end());
      from_greedy.insert(triangle);
    }
    std::set<std::pair<VertexIndex, VertexIndex>> seam_sides;
    for (const Triangle &triangle : seam)
      for (int k = 0; k < 3; ++k)
        seam_sides.insert(key(triangle[k], triangle[(k + 1) % 3]));
    const auto filled_at_seam = [&](const Triangle &triangle) {
      Triangle sorted = triangle;
      std::sort(sorted.begin(), sorted.end());
      if (from_greedy.count(sorted))
        return false;
      for (int k = 0; k < 3; ++k)
        if (seam_sides.count(key(triangle[k], triangle[(k + 1) % 3])))
          return true;
      return false;
    };
    triangles.erase(std::remove_if(triangles.begin(), triangles.end(), filled_at_seam),
                    triangles.end());
    finished = triangles.size();
    std::set<Triangle> present;
    for (Triangle triangle : triangles) {
      std::sort(triangle.begin(), triangle.end());
      present.insert(triangle);
    }
    for (const Triangle &triangle : seam) {
      Triangle sorted = triangle;
      std::sort(sorted.begin(), sorted.end());
      if (present.insert(sorted).second)
        triangles.push_back(triangle);
    }
  }
  // Triangles per undirected edge.
  std::map<std::pair<VertexIndex, VertexIndex>, std::vector<std::uint32_t>> on_edge;
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      on_edge[key(triangles[t][k], triangles[t][(k + 1) % 3])].push_back(t);
  // Whether t runs from a to b (rather than b to a).
  auto runs = [&](std::uint32_t t, VertexIndex a, VertexIndex b) {
    for (int k = 0; k < 3; ++k)
      if (triangles[t][k] == a && triangles[t][(k + 1) % 3] == b)
        return true;
    return false;
  };
  // Orientation per manifold sheet: the finished triangles keep theirs, and
  // each seam triangle takes its sheet's across edges with two triangles.
  std::vector<bool> oriented(triangles.size(), false);
  std::queue<std::uint32_t> work;
  for (std::uint32_t t = 0; t < finished; ++t) {
    oriented[t] = true;
    work.push(t);
  }
  for (std::uint32_t start = 0;; ++start) {
    while (!work.empty()) {
      const std::uint32_t t = work.front();
      work.pop();
      for (int k = 0; k < 3; ++k) {
        const VertexIndex a = triangles[t][k], b = triangles[t][(k + 1) % 3];
        const auto &users = on_edge[key(a, b)];
        if (users.size() != 2)
          continue;
        const std::uint32_t u = users[0] == t ? users[1] : users[0];
        if (oriented[u])
          continue;
        if (runs(u, a, b)) // consistent neighbours run the edge the other way
          std::swap(triangles[u][1], triangles[u][2]);
        oriented[u] = true;
        work.push(u);
      }
    }
    while (start < triangles.size() && oriented[start])
      ++start;
    if (start >= triangles.size())
      break;
    oriented[start] = true;
    work.push(start);
  }
  // Components are the manifold sheets; a sheet is orientable when every
  // edge inside it is run both ways.
  std::vector<std::uint32_t> parent(triangles.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t t) {
    while (parent[t] != t)
      t = parent[t] = parent[parent[t]];
    return t;
  };
  std::vector<std::array<VertexIndex, 2>> seam_edges;
  std::vector<std::pair<std::uint32_t, bool>> pairs; // first triangle, consistent
  for (const auto &[edge, users] : on_edge) {
    if (users.size() >= 3)
      seam_edges.push_back({edge.first, edge.second});
    if (users.size() != 2)
      continue;
    const std::uint32_t a = find(users[0]), b = find(users[1]);
    parent[std::max(a, b)] = std::min(a, b);
    pairs.emplace_back(users[0], runs(users[0], edge.first, edge.second) !=
                                     runs(users[1], edge.first, edge.second));
  }
  constexpr std::uint32_t no_component = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> component_of_root(triangles.size(), no_component);
  surface.triangle_component.assign(triangles.size(), 0);
  surface.component_orientable.clear();
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    const std::uint32_t root = find(t);
    if (component_of_root[root] == no_component) {
      component_of_root[root] = static_cast<std::uint32_t>(surface.component_orientable.size());
      surface.component_orientable.push_back(true);
    }
    surface.triangle_component[t] = component_of_root[root];
  }
  for (const auto &[t, consistent] : pairs)
    if (!consistent)
      surface.component_orientable[surface.triangle_component[t]] = false;
  surface.boundary_loops = traceBoundaryLoops(triangles);
  return seam_edges;
}

} // namespace pcl_ms
