// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4, finishing (docs/algorithm.md section 4). In: the greedy's
// triangles and the points. Out: a FinishedSurface: bow-ties split, small
// holes filled, folds cut, components oriented, boundary loops traced.
#include <pcl_ms/costs.h>
#include <pcl_ms/finish.h>
#include <pcl_ms/mesh_topology.h>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <map>
#include <numeric>
#include <queue>
#include <set>

namespace pcl_ms {
namespace {

using EdgeKey = std::uint64_t;

// An inconsistent edge that bends by more than this (90 degrees) is a fold,
// cut whatever its twist: a crumpled spot, never the gentle twist of a real
// Moebius band, which is kept and reported.
constexpr double max_untwist_bending = M_PI / 2;
constexpr int max_untwist_rounds = 3;
// A twist that an orientation-reversing walk of at most this many triangles
// closes is a crumple: the two triangles of its inconsistent edge are cut out
// and the hole refilled.
constexpr int max_local_twist_steps = 32;
// Or a walk of at most this many times the square root of the component's
// triangle count: a component's diameter in triangles is about that root.
// A real Moebius band reverses only all the way round, which is several
// times its root (10,000-point sampling: 823 steps, root 140); the longest
// twists left in PCL's scans closed within 109 steps (car6, root 118).
constexpr double max_twist_steps_per_root = 2.0;
// Holes of at most this many edges are filled without the size limit.
constexpr std::size_t max_unlimited_loop_edges = 4;
// Loops opened by cutting twists are closed again up to this size.
constexpr int max_untwist_loop_edges = 16;

EdgeKey edgeKey(VertexIndex a, VertexIndex b) {
  if (a > b)
    std::swap(a, b);
  return (static_cast<EdgeKey>(a) << 32) | b;
}

VertexIndex lowVertex(EdgeKey key) { return static_cast<VertexIndex>(key >> 32); }
VertexIndex highVertex(EdgeKey key) { return static_cast<VertexIndex>(key & 0xffffffffu); }

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

EdgeUses edgeUses(const std::vector<Triangle> &triangles) {
  VertexIndex vertex_count = 0;
  for (const Triangle &triangle : triangles)
    for (VertexIndex v : triangle)
      vertex_count = std::max(vertex_count, v + 1);
  EdgeUses result;
  std::vector<std::uint32_t> &offsets = result.offsets;
  offsets.assign(static_cast<std::size_t>(vertex_count) + 1, 0);
  for (const Triangle &triangle : triangles)
    for (int k = 0; k < 3; ++k)
      ++offsets[lowVertex(edgeKey(triangle[k], triangle[(k + 1) % 3])) + 1];
  for (std::size_t v = 0; v < vertex_count; ++v)
    offsets[v + 1] += offsets[v];
  result.uses.resize(3 * triangles.size());
  std::vector<std::uint32_t> cursor(offsets.begin(), offsets.end() - 1);
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const EdgeKey key = edgeKey(triangles[t][k], triangles[t][(k + 1) % 3]);
      result.uses[cursor[lowVertex(key)]++] = {highVertex(key), t};
    }
  forEachIndex(vertex_count, [&](std::size_t v) {
    std::sort(result.uses.begin() + offsets[v], result.uses.begin() + offsets[v + 1]);
  });
  return result;
}

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

/// Whether triangle t, as stored, runs from a to b.
bool runsFromTo(const Triangle &t, VertexIndex a, VertexIndex b) {
  for (int k = 0; k < 3; ++k)
    if (t[k] == a && t[(k + 1) % 3] == b)
      return true;
  return false;
}

/// Minimum-cost triangulation of one boundary loop, or nothing. With
/// delaunay_only, its triangles are facets of the loop's own Delaunay
/// triangulation, which keeps the filling from folding; a noisy loop that
/// twists in 3-D often has no such triangulation.
std::vector<Triangle> triangulateLoop(const std::vector<VertexIndex> &loop,
                                      const std::vector<Eigen::Vector3d> &points,
                                      const std::vector<EdgeKey> &mesh_edges,
                                      const SideLimit &limit, bool delaunay_only) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using VertexBase = CGAL::Triangulation_vertex_base_with_info_3<std::size_t, Kernel>;
  using DataStructure = CGAL::Triangulation_data_structure_3<VertexBase>;
  using Delaunay = CGAL::Delaunay_triangulation_3<Kernel, DataStructure>;

  const std::size_t m = loop.size();
  // A loop is one hole: like a triangle against its largest corner scale,
  // its filling is held to the largest scale on its rim.
  float rim_scale = 0;
  for (VertexIndex v : loop)
    rim_scale = std::max(rim_scale, (*limit.point_scale)[v]);
  const double max_side = limit.rho * rim_scale;
  std::set<std::array<std::size_t, 3>> allowed;
  if (delaunay_only) {
    std::vector<std::pair<Kernel::Point_3, std::size_t>> input;
    for (std::size_t i = 0; i < m; ++i) {
      const Eigen::Vector3d &p = points[loop[i]];
      input.emplace_back(Kernel::Point_3(p.x(), p.y(), p.z()), i);
    }
    const Delaunay delaunay(input.begin(), input.end());
    if (delaunay.dimension() < 2)
      return {};
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
        if (best[i][k] == infinity || best[k][j] == infinity ||
            (delaunay_only && !allowed.count({i, k, j})))
          continue;
        const TriangleShape shape =
            triangleShape(points[loop[i]], points[loop[k]], points[loop[j]]);
        // A hole of three or four edges takes its triangles whatever their
        // size (a missing triangle or quad between the greedy's triangles,
        // whose new sides are at most two of its edges long); larger loops
        // keep the greedy's size limit, or fillings would reach across
        // concave spots.
        if (shape.compactness <= 0 ||
            (m > max_unlimited_loop_edges && shape.longest_side >= max_side))
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

namespace {

std::vector<std::vector<VertexIndex>> boundaryLoops(const EdgeUses &uses) {
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

/// Closes loops of at most max_edges edges with triangles of the Delaunay
/// triangulation of the loop's vertices (minimum total P / C^2, no edge
/// that the mesh already has inside the hole, sides below the limit except
/// for a triangular hole), or any triangles when those cannot fill it
/// (docs/algorithm.md, "Finishing"). Only simple loops; with only_around,
/// only loops through a vertex marked there. Returns the holes closed.
std::size_t fillLoops(std::vector<Triangle> &triangles, std::vector<std::vector<VertexIndex>> loops,
                      const std::vector<Eigen::Vector3d> &points, int max_edges,
                      const SideLimit &limit, const std::vector<bool> *only_around) {
  if (max_edges < 3)
    return 0;
  // Only simple loops: a vertex met twice is a pinch the polygon DP cannot
  // fill; with only_around, only loops that reach the marked vertices.
  loops.erase(std::remove_if(loops.begin(), loops.end(),
                             [&](const std::vector<VertexIndex> &loop) {
                               std::vector<VertexIndex> sorted = loop;
                               std::sort(sorted.begin(), sorted.end());
                               if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
                                 return true;
                               return only_around &&
                                      std::none_of(loop.begin(), loop.end(), [&](VertexIndex v) {
                                        return (*only_around)[v];
                                      });
                             }),
              loops.end());
  const bool any_small_loop = std::any_of(loops.begin(), loops.end(), [&](const auto &loop) {
    return loop.size() <= static_cast<std::size_t>(max_edges);
  });
  if (!any_small_loop)
    return 0;
  // Existing edges and triangles matter only where all their corners are
  // on a loop that may be filled: that keeps these lists short.
  std::vector<bool> on_small_loop(points.size(), false);
  for (const auto &loop : loops)
    if (loop.size() <= static_cast<std::size_t>(max_edges))
      for (VertexIndex v : loop)
        on_small_loop[v] = true;
  std::vector<EdgeKey> mesh_edges;
  for (const Triangle &t : triangles)
    for (int k = 0; k < 3; ++k)
      if (on_small_loop[t[k]] && on_small_loop[t[(k + 1) % 3]])
        mesh_edges.push_back(edgeKey(t[k], t[(k + 1) % 3]));
  std::sort(mesh_edges.begin(), mesh_edges.end());
  mesh_edges.erase(std::unique(mesh_edges.begin(), mesh_edges.end()), mesh_edges.end());
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
    // Any triangles where the loop's Delaunay facets cannot fill it: the
    // size limit still holds, and a fold the filling makes is repaired with
    // the others. Kinect frames kept a quarter of their loops without this
    // (office1.pcd: 691 loops, now 599).
    std::vector<Triangle> filling = triangulateLoop(loop, points, mesh_edges, limit, true);
    if (filling.empty())
      filling = triangulateLoop(loop, points, mesh_edges, limit, false);
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

} // namespace

std::vector<std::vector<VertexIndex>> traceBoundaryLoops(const std::vector<Triangle> &triangles) {
  return boundaryLoops(edgeUses(triangles));
}

namespace {

/// Union-find over triangles that keeps each triangle's flip relative to its
/// root. The smaller index is always the root, so a set's root is its first
/// triangle whatever order the joins come in.
class ParityForest {
public:
  enum class Join { joined, consistent, conflict };

  explicit ParityForest(std::size_t size) : parent_(size), flip_to_parent_(size, 0) {
    std::iota(parent_.begin(), parent_.end(), 0u);
  }

  /// The root of t, and whether t is flipped relative to it.
  std::pair<std::uint32_t, std::uint8_t> find(std::uint32_t t) {
    std::uint8_t flip = 0;
    std::uint32_t root = t;
    while (parent_[root] != root) {
      flip ^= flip_to_parent_[root];
      root = parent_[root];
    }
    // Path compression: point every triangle on the path at the root.
    for (std::uint8_t rest = flip; parent_[t] != t;) {
      const std::uint32_t next = parent_[t];
      const std::uint8_t step = flip_to_parent_[t];
      parent_[t] = root;
      flip_to_parent_[t] = rest;
      rest ^= step;
      t = next;
    }
    return {root, flip};
  }

  /// Puts t and u in one set with their flips differing by must_differ; when
  /// they already share a set, says whether their flips agree with that.
  Join join(std::uint32_t t, std::uint32_t u, bool must_differ) {
    const auto [t_root, t_flip] = find(t);
    const auto [u_root, u_flip] = find(u);
    if (t_root == u_root)
      return (t_flip ^ u_flip) == must_differ ? Join::consistent : Join::conflict;
    const std::uint32_t root = std::min(t_root, u_root);
    const std::uint32_t child = std::max(t_root, u_root);
    parent_[child] = root;
    flip_to_parent_[child] = static_cast<std::uint8_t>(t_flip ^ u_flip ^ must_differ);
    return Join::joined;
  }

private:
  std::vector<std::uint32_t> parent_;
  std::vector<std::uint8_t> flip_to_parent_;
};

// Pairs bending less than this (about 30 degrees) are joined before the
// rest without sorting (see orientPairs); any value gives the same
// orientation, this one leaves few pairs to sort on a smooth surface.
constexpr double kruskal_flat_bending = 0.5;

/// Two triangles sharing a manifold edge and the edge's end points (how much
/// the surface bends there is bendingAt(), computed where orientation needs it).
struct ManifoldPair {
  std::uint32_t first, second;
  VertexIndex a, b; // the shared edge
};

std::vector<ManifoldPair> manifoldPairs(const EdgeUses &uses) {
  std::size_t count_of_pairs = 0;
  forEachEdge(uses, [&](EdgeKey, std::size_t, std::size_t count) { count_of_pairs += count == 2; });
  std::vector<ManifoldPair> pairs;
  pairs.reserve(count_of_pairs);
  forEachEdge(uses, [&](EdgeKey key, std::size_t first, std::size_t count) {
    if (count == 2)
      pairs.push_back({uses.uses[first].triangle, uses.uses[first + 1].triangle, lowVertex(key),
                       highVertex(key)});
  });
  return pairs;
}

double bendingAt(const ManifoldPair &pair, const std::vector<Triangle> &triangles,
                 const std::vector<Eigen::Vector3d> &points) {
  auto apex = [&](std::uint32_t t) {
    for (VertexIndex v : triangles[t])
      if (v != pair.a && v != pair.b)
        return v;
    return pair.a;
  };
  return bendingAngle(points[pair.a], points[pair.b], points[apex(pair.first)],
                      points[apex(pair.second)]);
}

/// Whether t and u run their shared edge in opposite directions.
bool consistentlyOriented(const Triangle &t, const Triangle &u) {
  for (int k = 0; k < 3; ++k)
    if (runsFromTo(u, t[(k + 1) % 3], t[k]))
      return true;
  return false;
}

/// The triangles at each marked vertex: one scan of the mesh, and memory
/// for the marked vertices only (a few, or a seam's, of a large mesh).
class MarkedIncidence {
public:
  MarkedIncidence(const std::vector<Triangle> &triangles, const std::vector<bool> &marked) {
    for (VertexIndex v = 0; v < marked.size(); ++v)
      if (marked[v])
        vertices_.push_back(v);
    at_.resize(vertices_.size());
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      for (VertexIndex v : triangles[t])
        if (v < marked.size() && marked[v])
          at_[slot(v)].push_back(t);
  }
  const std::vector<VertexIndex> &vertices() const { return vertices_; }
  const std::vector<std::uint32_t> &atSlot(std::size_t slot) const { return at_[slot]; }
  const std::vector<std::uint32_t> &at(VertexIndex v) const { return at_[slot(v)]; }

private:
  std::size_t slot(VertexIndex v) const {
    return static_cast<std::size_t>(std::lower_bound(vertices_.begin(), vertices_.end(), v) -
                                    vertices_.begin());
  }
  std::vector<VertexIndex> vertices_; // ascending
  std::vector<std::vector<std::uint32_t>> at_;
};

/// The triangles at v (given in `around`) grouped into fans joined by edges at v.
std::vector<std::vector<std::uint32_t>> fansAt(VertexIndex v,
                                               const std::vector<std::uint32_t> &around,
                                               const std::vector<Triangle> &triangles) {
  auto otherCorners = [&](std::uint32_t t) {
    std::array<VertexIndex, 2> corners{};
    int n = 0;
    for (VertexIndex w : triangles[t])
      if (w != v && n < 2)
        corners[n++] = w;
    return corners;
  };
  // Two triangles at v are in one fan when they share a second corner.
  const auto groups = connectedGroups(around.size(), [&](const auto &join) {
    for (std::size_t i = 0; i < around.size(); ++i)
      for (std::size_t j = i + 1; j < around.size(); ++j) {
        const auto a = otherCorners(around[i]), b = otherCorners(around[j]);
        if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1])
          join(i, j);
      }
  });
  std::vector<std::vector<std::uint32_t>> fans(groups.size());
  for (std::size_t f = 0; f < groups.size(); ++f)
    for (std::size_t i : groups[f])
      fans[f].push_back(around[i]);
  return fans;
}

/// Drops the marked triangles; their corners are marked in touched.
void dropTriangles(std::vector<Triangle> &triangles, const std::vector<bool> &drop,
                   std::vector<bool> &touched) {
  std::size_t write = 0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    if (drop[t])
      for (VertexIndex v : triangles[t])
        touched[v] = true;
    else
      triangles[write++] = triangles[t];
  }
  triangles.resize(write);
}

} // namespace

std::size_t splitBowTies(std::vector<Triangle> &triangles, std::size_t vertex_count,
                         std::vector<bool> &touched) {
  const std::size_t before = triangles.size();
  touched.resize(vertex_count, false);
  for (bool changed = true; changed;) {
    changed = false;
    const MarkedIncidence incidence(triangles, touched);
    std::vector<bool> drop(triangles.size(), false);
    for (std::size_t slot = 0; slot < incidence.vertices().size(); ++slot) {
      const VertexIndex v = incidence.vertices()[slot];
      if (incidence.atSlot(slot).size() < 2)
        continue;
      const auto fans = fansAt(v, incidence.atSlot(slot), triangles);
      if (fans.size() < 2)
        continue;
      std::size_t keep = 0;
      for (std::size_t f = 1; f < fans.size(); ++f)
        if (fans[f].size() > fans[keep].size())
          keep = f;
      for (std::size_t f = 0; f < fans.size(); ++f)
        if (f != keep)
          for (std::uint32_t t : fans[f])
            drop[t] = changed = true;
    }
    if (changed)
      dropTriangles(triangles, drop, touched);
  }
  return before - triangles.size();
}

namespace {

/// Whether a walk of at most max_steps triangles from `start` across
/// manifold pairs returns to it with its orientation reversed (crossing a
/// pair flagged in `flips` reverses it): breadth first over (triangle,
/// reversed) states. `reached` has one entry per triangle, all 0 (bit 0:
/// reached as it is, bit 1: reversed), and is left so.
bool reversesWithin(std::uint32_t start, int max_steps, const std::vector<ManifoldPair> &pairs,
                    const std::vector<std::uint32_t> &offsets,
                    const std::vector<std::uint32_t> &incident,
                    const std::vector<std::uint8_t> &flips, std::vector<std::uint8_t> &reached) {
  using State = std::pair<std::uint32_t, bool>;
  std::vector<State> frontier = {{start, false}}, next;
  std::vector<std::uint32_t> touched = {start};
  reached[start] = 1;
  bool reverses = false;
  for (int step = 0; step < max_steps && !frontier.empty() && !reverses; ++step) {
    next.clear();
    for (const auto &[t, reversed] : frontier)
      for (std::uint32_t i = offsets[t]; i < offsets[t + 1] && !reverses; ++i) {
        const ManifoldPair &pair = pairs[incident[i]];
        const State state{pair.first == t ? pair.second : pair.first,
                          reversed != (flips[incident[i]] != 0)};
        reverses = state.first == start && state.second;
        const std::uint8_t bit = state.second ? 2 : 1;
        if (reached[state.first] & bit)
          continue;
        if (reached[state.first] == 0)
          touched.push_back(state.first);
        reached[state.first] |= bit;
        next.push_back(state);
      }
    frontier.swap(next);
  }
  for (std::uint32_t t : touched)
    reached[t] = 0;
  return reverses;
}

/// orientComponents() given the mesh's manifold pairs.
std::vector<std::uint32_t> orientPairs(std::vector<Triangle> &triangles,
                                       const std::vector<ManifoldPair> &pairs,
                                       const std::vector<Eigen::Vector3d> &points,
                                       std::vector<std::uint32_t> &triangle_component,
                                       std::vector<bool> &component_orientable,
                                       const Eigen::Vector3d *viewpoint) {
  const std::uint32_t unvisited = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> offsets(triangles.size() + 1, 0);
  for (const ManifoldPair &pair : pairs) {
    ++offsets[pair.first + 1];
    ++offsets[pair.second + 1];
  }
  for (std::size_t t = 0; t < triangles.size(); ++t)
    offsets[t + 1] += offsets[t];
  std::vector<std::uint32_t> incident(offsets.back());
  {
    std::vector<std::uint32_t> cursor(offsets.begin(), offsets.end() - 1);
    for (std::uint32_t p = 0; p < pairs.size(); ++p) {
      incident[cursor[pairs[p].first]++] = p;
      incident[cursor[pairs[p].second]++] = p;
    }
  }
  // Sets the orientation of `next` from its already oriented neighbour.
  auto orientAcross = [&](const ManifoldPair &pair, std::uint32_t component) {
    const bool first_known = triangle_component[pair.first] == component;
    const std::uint32_t known = first_known ? pair.first : pair.second;
    const std::uint32_t next = first_known ? pair.second : pair.first;
    if (!consistentlyOriented(triangles[known], triangles[next]))
      std::swap(triangles[next][1], triangles[next][2]);
    triangle_component[next] = component;
    return next;
  };

  // A consistent orientation, where one exists, is the same whatever order
  // it spreads in: breadth first, each component from its first triangle.
  triangle_component.assign(triangles.size(), unvisited);
  component_orientable.clear();
  std::vector<std::vector<std::uint32_t>> members;
  for (std::uint32_t seed = 0; seed < triangles.size(); ++seed) {
    if (triangle_component[seed] != unvisited)
      continue;
    const std::uint32_t component = static_cast<std::uint32_t>(component_orientable.size());
    component_orientable.push_back(true);
    members.push_back({seed});
    triangle_component[seed] = component;
    std::vector<std::uint32_t> &queue = members.back();
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const std::uint32_t t = queue[head];
      for (std::uint32_t i = offsets[t]; i < offsets[t + 1]; ++i) {
        const ManifoldPair &pair = pairs[incident[i]];
        if (triangle_component[pair.first] == unvisited ||
            triangle_component[pair.second] == unvisited)
          queue.push_back(orientAcross(pair, component));
      }
    }
  }
  // Per pair, whether its triangles disagree now; read until Kruskal flips.
  std::vector<std::uint8_t> inconsistent(pairs.size());
  forEachIndex(pairs.size(), [&](std::size_t p) {
    inconsistent[p] = !consistentlyOriented(triangles[pairs[p].first], triangles[pairs[p].second]);
  });
  for (std::size_t p = 0; p < pairs.size(); ++p)
    if (inconsistent[p])
      component_orientable[triangle_component[pairs[p].first]] = false;

  // Where none exists, orientation follows a maximum spanning forest on
  // flatness (pairs joined flattest first, Kruskal's order), so that the
  // edges left inconsistent are the component's most bent ones, i.e. where
  // the twist is. Each component's first triangle keeps its orientation.
  auto inTwistedComponent = [&](std::size_t p) {
    return !component_orientable[triangle_component[pairs[p].first]];
  };
  const bool any_twisted = std::find(component_orientable.begin(), component_orientable.end(),
                                     false) != component_orientable.end();
  std::vector<std::uint32_t> to_cut;
  if (any_twisted) {
    std::vector<double> bending(pairs.size(), 0.0); // in twisted components only
    forEachIndex(pairs.size(), [&](std::size_t p) {
      if (inTwistedComponent(p))
        bending[p] = bendingAt(pairs[p], triangles, points);
    });
    // Kruskal's forest after the flat pairs does not depend on their order
    // when no cycle of flat pairs is twisted: the same triangles end up
    // together with the same relative flips. So they are joined unsorted,
    // and only the few bent pairs are sorted. A twist among flat pairs
    // needs Kruskal's order throughout.
    std::vector<std::uint32_t> flat_pairs, bent_pairs;
    for (std::uint32_t p = 0; p < pairs.size(); ++p)
      if (inTwistedComponent(p))
        (bending[p] < kruskal_flat_bending ? flat_pairs : bent_pairs).push_back(p);
    ParityForest forest(triangles.size());
    // Flipping exactly one of a pair changes whether the two agree.
    auto join = [&](std::uint32_t p) {
      return forest.join(pairs[p].first, pairs[p].second, inconsistent[p]);
    };
    bool flat_cycle_twisted = false;
    for (std::uint32_t p : flat_pairs)
      flat_cycle_twisted |= join(p) == ParityForest::Join::conflict;
    if (flat_cycle_twisted) {
      forest = ParityForest(triangles.size());
      bent_pairs.insert(bent_pairs.end(), flat_pairs.begin(), flat_pairs.end());
    }
    std::sort(bent_pairs.begin(), bent_pairs.end(), [&](std::uint32_t p, std::uint32_t q) {
      return bending[p] < bending[q] || (bending[p] == bending[q] && p < q);
    });
    // A pair that closes a cycle leaves the forest as it is, consistent or not.
    for (std::uint32_t p : bent_pairs)
      join(p);
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      if (!component_orientable[triangle_component[t]] && forest.find(t).second)
        std::swap(triangles[t][1], triangles[t][2]);

    std::vector<std::uint8_t> conflict(pairs.size());
    forEachIndex(pairs.size(), [&](std::size_t p) {
      conflict[p] = inTwistedComponent(p) &&
                    !consistentlyOriented(triangles[pairs[p].first], triangles[pairs[p].second]);
    });
    // A conflict is repaired where the surface folds sharply, or where the
    // twist it closes is local: an orientation-reversing walk that is short
    // for the component returns to its triangle (a crumple). A real Moebius
    // band reverses orientation only all the way around (docs/algorithm.md).
    // The long walk is tried until one conflict of a component fails it:
    // that component holds a real twist, and the walks would cost the
    // component's size each.
    //
    // With a viewpoint, every conflict is repaired: seen from one point a
    // surface cannot fold over itself. Of the two triangles of a fold, the
    // one seen more edge-on goes (the other is the surface the sensor saw).
    // Cutting fans or both triangles there left office1.pcd in 797 pieces
    // with 1,108 loops; this rule, 291 and 691.
    auto moreEdgeOn = [&](const ManifoldPair &pair) {
      auto facing = [&](std::uint32_t t) {
        const Eigen::Vector3d &a = points[triangles[t][0]], &b = points[triangles[t][1]],
                              &c = points[triangles[t][2]];
        const Eigen::Vector3d normal = (b - a).cross(c - a);
        const Eigen::Vector3d to_viewpoint = *viewpoint - (a + b + c) / 3;
        const double lengths = normal.norm() * to_viewpoint.norm();
        return lengths > 0 ? std::abs(normal.dot(to_viewpoint)) / lengths : 0.0;
      };
      return facing(pair.first) < facing(pair.second) ? pair.first : pair.second;
    };
    std::vector<std::uint8_t> reached(triangles.size(), 0);
    std::vector<bool> holds_real_twist(members.size(), false);
    for (std::uint32_t p = 0; p < pairs.size(); ++p) {
      if (!conflict[p])
        continue;
      const std::uint32_t component = triangle_component[pairs[p].first];
      const int long_walk = static_cast<int>(
          max_twist_steps_per_root * std::sqrt(static_cast<double>(members[component].size())));
      auto localTwist = [&]() {
        if (reversesWithin(pairs[p].first, max_local_twist_steps, pairs, offsets, incident,
                           conflict, reached))
          return true;
        if (holds_real_twist[component] || long_walk <= max_local_twist_steps)
          return false;
        if (reversesWithin(pairs[p].first, long_walk, pairs, offsets, incident, conflict, reached))
          return true;
        holds_real_twist[component] = true;
        return false;
      };
      if (viewpoint)
        to_cut.push_back(moreEdgeOn(pairs[p]));
      else if (bending[p] > max_untwist_bending || localTwist()) {
        to_cut.push_back(pairs[p].first);
        to_cut.push_back(pairs[p].second);
      }
    }
  }
  for (std::uint32_t component = 0; component < members.size(); ++component) {
    if (!component_orientable[component])
      continue;
    // Outward for closed surfaces; towards the viewpoint for open ones when
    // there is one (area-weighted); a fixed, reproducible choice otherwise.
    double signed_volume = 0, facing = 0;
    bool closed = true;
    for (std::uint32_t t : members[component]) {
      const Eigen::Vector3d &a = points[triangles[t][0]], &b = points[triangles[t][1]],
                            &c = points[triangles[t][2]];
      signed_volume += a.dot(b.cross(c));
      if (viewpoint)
        facing += (b - a).cross(c - a).dot(*viewpoint - a);
      closed = closed && offsets[t + 1] - offsets[t] == 3;
    }
    if ((viewpoint && !closed ? facing : signed_volume) < 0)
      for (std::uint32_t t : members[component])
        std::swap(triangles[t][1], triangles[t][2]);
  }
  return to_cut;
}

} // namespace

std::vector<std::uint32_t> orientComponents(std::vector<Triangle> &triangles,
                                            const std::vector<Eigen::Vector3d> &points,
                                            std::vector<std::uint32_t> &triangle_component,
                                            std::vector<bool> &component_orientable,
                                            const Eigen::Vector3d *viewpoint) {
  return orientPairs(triangles, manifoldPairs(edgeUses(triangles)), points, triangle_component,
                     component_orientable, viewpoint);
}

FinishedSurface finishSurface(std::vector<Triangle> triangles,
                              const std::vector<Eigen::Vector3d> &points, int fill_holes_max_edges,
                              const SideLimit &limit, const std::vector<bool> *anchored_vertices,
                              const Eigen::Vector3d *viewpoint) {
  FinishedSurface surface;
  // Edge uses are built once per set of triangles. Orienting keeps the set,
  // so the boundary loops are traced before it and the uses freed: the
  // orientation's own arrays are as large.
  auto fillThenOrient = [&](int max_edges, const std::vector<bool> *only_around) {
    EdgeUses uses = edgeUses(triangles);
    surface.boundary_loops = boundaryLoops(uses);
    const std::size_t filled =
        fillLoops(triangles, surface.boundary_loops, points, max_edges, limit, only_around);
    if (filled > 0) {
      uses = edgeUses(triangles);
      surface.boundary_loops = boundaryLoops(uses);
    }
    surface.holes_filled += filled;
    const std::vector<ManifoldPair> pairs = manifoldPairs(uses);
    uses = EdgeUses();
    return orientPairs(triangles, pairs, points, surface.triangle_component,
                       surface.component_orientable, viewpoint);
  };
  std::vector<std::uint32_t> to_cut = fillThenOrient(fill_holes_max_edges, nullptr);
  for (int round = 0; round < max_untwist_rounds && !to_cut.empty(); ++round) {
    // Only the triangles at the inconsistent edges go, never whole fans:
    // cutting the most crumpled corner's fan at sharp folds split sparse
    // scans and the camel head apart (car6: 80 pieces instead of 52).
    std::vector<bool> drop(triangles.size(), false);
    for (std::uint32_t t : to_cut)
      drop[t] = !anchored_vertices ||
                std::none_of(triangles[t].begin(), triangles[t].end(),
                             [&](VertexIndex v) { return (*anchored_vertices)[v]; });
    const std::size_t before = triangles.size();
    std::vector<bool> touched(points.size(), false);
    dropTriangles(triangles, drop, touched);
    splitBowTies(triangles, points.size(), touched);
    surface.twist_triangles_removed += before - triangles.size();
    // The loops that removal opened are ours to close, whatever the user's limit.
    to_cut = fillThenOrient(max_untwist_loop_edges, &touched);
  }
  surface.triangles = std::move(triangles);
  return surface;
}

} // namespace pcl_ms

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
