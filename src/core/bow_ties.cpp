// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4, bow-ties (docs/algorithm.md section 4, "Bow-ties"). In: a triangle
// list and the vertices to check. Out: the list with one fan (the largest,
// by the rule of fan_choice.h) left at each of them; corners of removed
// triangles are checked in turn.
#include "fan_choice.h"
#include "finish_steps.h"

#include <pcl_ms/mesh_topology.h>

#include <boost/container/small_vector.hpp>

#include <algorithm>
#include <array>
#include <functional>
#include <numeric>

namespace pcl_ms {
namespace detail {
namespace {

/// The triangles at each marked vertex, those marked `gone` left out, in
/// ascending order: one scan of the mesh, and memory for the marked
/// vertices only (a few, or a seam's, of a large mesh). A vertex's slot is
/// its rank among the marked ones, read from a bit per vertex and a count
/// per 64 of them.
class MarkedIncidence {
public:
  MarkedIncidence(const std::vector<Triangle> &triangles, const std::vector<bool> &marked,
                  const std::vector<bool> &gone)
      : bits_((marked.size() + 63) / 64, 0), ranks_(bits_.size(), 0) {
    for (VertexIndex v = 0; v < marked.size(); ++v)
      if (marked[v]) {
        bits_[v / 64] |= std::uint64_t{1} << (v % 64);
        vertices_.push_back(v);
      }
    for (std::size_t word = 1; word < bits_.size(); ++word)
      ranks_[word] = ranks_[word - 1] + static_cast<std::uint32_t>(popcount(bits_[word - 1]));
    offsets_.assign(vertices_.size() + 1, 0);
    forEachMarkedCorner(triangles, gone,
                        [&](std::uint32_t, std::size_t slot) { ++offsets_[slot + 1]; });
    std::partial_sum(offsets_.begin(), offsets_.end(), offsets_.begin());
    std::vector<std::uint32_t> cursor(offsets_.begin(), offsets_.end() - 1);
    at_.resize(offsets_.back());
    forEachMarkedCorner(triangles, gone,
                        [&](std::uint32_t t, std::size_t slot) { at_[cursor[slot]++] = t; });
  }
  const std::vector<VertexIndex> &vertices() const { return vertices_; }
  const std::uint32_t *begin(std::size_t slot) const { return at_.data() + offsets_[slot]; }
  const std::uint32_t *end(std::size_t slot) const { return at_.data() + offsets_[slot + 1]; }

private:
  static int popcount(std::uint64_t word) { return __builtin_popcountll(word); }

  bool isMarked(VertexIndex v) const {
    return v / 64 < bits_.size() && (bits_[v / 64] >> (v % 64) & 1) != 0;
  }
  std::size_t slot(VertexIndex v) const {
    const std::uint64_t below = bits_[v / 64] & ((std::uint64_t{1} << (v % 64)) - 1);
    return ranks_[v / 64] + static_cast<std::size_t>(popcount(below));
  }
  template <typename Visit>
  void forEachMarkedCorner(const std::vector<Triangle> &triangles, const std::vector<bool> &gone,
                           const Visit &visit) const {
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      if (!gone[t])
        for (VertexIndex v : triangles[t])
          if (isMarked(v))
            visit(t, slot(v));
  }

  std::vector<std::uint64_t> bits_;   // one per vertex: marked
  std::vector<std::uint32_t> ranks_;  // marked vertices before each word's first
  std::vector<VertexIndex> vertices_; // ascending
  std::vector<std::uint32_t> offsets_, at_;
};

/// The two corners of triangle t other than v.
std::array<VertexIndex, 2> otherCorners(VertexIndex v, const Triangle &triangle) {
  std::array<VertexIndex, 2> corners{};
  int n = 0;
  for (VertexIndex w : triangle)
    if (w != v && n < 2)
      corners[n++] = w;
  return corners;
}

/// Whether two triangles at v share a second corner, i.e. an edge at v.
bool shareEdgeAt(VertexIndex v, const Triangle &a_triangle, const Triangle &b_triangle) {
  const auto a = otherCorners(v, a_triangle), b = otherCorners(v, b_triangle);
  return a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1];
}

/// Whether the triangles [first, last) at v form one fan. Most vertices'
/// do: this answers without allocating, and only the rest are grouped.
bool isOneFan(VertexIndex v, const std::uint32_t *first, const std::uint32_t *last,
              const std::vector<Triangle> &triangles) {
  const std::size_t count = static_cast<std::size_t>(last - first);
  boost::container::small_vector<std::uint32_t, 32> parent(count);
  std::iota(parent.begin(), parent.end(), 0u);
  auto root = [&](std::uint32_t i) {
    while (parent[i] != i)
      i = parent[i] = parent[parent[i]];
    return i;
  };
  std::size_t groups = count;
  for (std::uint32_t i = 0; i < count; ++i)
    for (std::uint32_t j = i + 1; j < count; ++j)
      if (shareEdgeAt(v, triangles[first[i]], triangles[first[j]])) {
        const std::uint32_t a = root(i), b = root(j);
        if (a != b) {
          parent[std::max(a, b)] = std::min(a, b);
          --groups;
        }
      }
  return groups == 1;
}

/// The `count` triangles at v listed at `around`, grouped into fans joined
/// by edges at v.
std::vector<std::vector<std::uint32_t>> fansAt(VertexIndex v, const std::uint32_t *around,
                                               std::size_t count,
                                               const std::vector<Triangle> &triangles) {
  const auto groups = connectedGroups(count, [&](const auto &join) {
    for (std::size_t i = 0; i < count; ++i)
      for (std::size_t j = i + 1; j < count; ++j)
        if (shareEdgeAt(v, triangles[around[i]], triangles[around[j]]))
          join(i, j);
  });
  std::vector<std::vector<std::uint32_t>> fans(groups.size());
  for (std::size_t f = 0; f < groups.size(); ++f)
    for (std::size_t i : groups[f])
      fans[f].push_back(around[i]);
  return fans;
}

/// One round's drops at every marked vertex, in the order of the vertices:
/// they read the same incidence, so blocks of them run in parallel.
std::vector<std::uint32_t> dropFromMarked(const MarkedIncidence &incidence,
                                          const std::vector<Triangle> &triangles,
                                          const std::function<bool(std::uint32_t)> &is_fixed) {
  constexpr std::size_t block = 1 << 12;
  const std::size_t count = incidence.vertices().size();
  std::vector<std::vector<std::uint32_t>> drops((count + block - 1) / block);
  parallelFor(std::size_t(0), drops.size(), [&](std::size_t b) {
    for (std::size_t slot = b * block; slot < std::min(count, (b + 1) * block); ++slot)
      dropBowTieFans(incidence.vertices()[slot], incidence.begin(slot), incidence.end(slot),
                     triangles, is_fixed, drops[b]);
  });
  std::vector<std::uint32_t> drop;
  for (const std::vector<std::uint32_t> &part : drops)
    drop.insert(drop.end(), part.begin(), part.end());
  return drop;
}

} // namespace

void dropBowTieFans(VertexIndex v, const std::uint32_t *first, const std::uint32_t *last,
                    const std::vector<Triangle> &triangles,
                    const std::function<bool(std::uint32_t)> &is_fixed,
                    std::vector<std::uint32_t> &drop) {
  if (last - first < 2 || isOneFan(v, first, last, triangles))
    return;
  const auto fans = fansAt(v, first, static_cast<std::size_t>(last - first), triangles);
  if (fans.size() < 2)
    return;
  const std::size_t keep = fanToKeep(fans.size(), [&](std::size_t f) {
    FanWeight weight;
    if (is_fixed)
      weight.fixed =
          static_cast<std::size_t>(std::count_if(fans[f].begin(), fans[f].end(), is_fixed));
    weight.size = fans[f].size();
    return weight;
  });
  for (std::size_t f = 0; f < fans.size(); ++f)
    if (f != keep)
      for (std::uint32_t t : fans[f])
        if (!is_fixed || !is_fixed(t))
          drop.push_back(t);
}

void dropTriangles(std::vector<Triangle> &triangles, const std::vector<bool> &drop,
                   std::vector<bool> &touched, MeshEdges *edges) {
  const bool scan_again = edges && !dropFromMeshEdges(*edges, triangles, drop);
  std::size_t write = 0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    if (drop[t])
      for (VertexIndex v : triangles[t])
        touched[v] = true;
    else
      triangles[write++] = triangles[t];
  }
  triangles.resize(write);
  if (scan_again) {
    *edges = MeshEdges(); // not held while the new ones are made
    *edges = meshEdges(triangles, true);
  }
}

std::size_t splitBowTies(std::vector<Triangle> &triangles, std::size_t vertex_count,
                         std::vector<bool> &touched, const std::vector<Triangle> *fixed,
                         MeshEdges *edges) {
  const std::size_t before = triangles.size();
  std::function<bool(std::uint32_t)> isFixed;
  if (fixed)
    isFixed = [&](std::uint32_t t) {
      Triangle corners = triangles[t];
      std::sort(corners.begin(), corners.end());
      return std::binary_search(fixed->begin(), fixed->end(), corners);
    };
  touched.resize(vertex_count, false);
  // After the first round only the corners of what it removed can have
  // gained a second fan: the other vertices kept their triangles. The
  // removed triangles leave the list once, after the last round (each
  // removal renumbers the list and the edge scan), and are skipped until
  // then: their order, and so every choice, is the same.
  std::vector<bool> check = touched;
  std::vector<bool> removed(triangles.size(), false);
  bool any_removed = false;
  for (bool changed = true; changed;) {
    changed = false;
    const MarkedIncidence incidence(triangles, check, removed);
    const std::vector<std::uint32_t> drop = dropFromMarked(incidence, triangles, isFixed);
    if (!drop.empty()) {
      changed = any_removed = true;
      std::fill(check.begin(), check.end(), false);
      for (std::uint32_t t : drop) {
        removed[t] = true;
        for (VertexIndex v : triangles[t])
          check[v] = touched[v] = true;
      }
    }
  }
  if (any_removed)
    dropTriangles(triangles, removed, touched, edges);
  return before - triangles.size();
}

} // namespace detail

std::size_t splitBowTies(std::vector<Triangle> &triangles, std::size_t vertex_count,
                         std::vector<bool> &touched, const std::vector<Triangle> *fixed) {
  return detail::splitBowTies(triangles, vertex_count, touched, fixed, nullptr);
}

} // namespace pcl_ms
