// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4, bow-ties (docs/algorithm.md section 4, "Bow-ties"). In: a triangle
// list and the vertices to check. Out: the list with one fan (the largest,
// by the rule of fan_choice.h) left at each of them; corners of removed
// triangles are checked in turn.
#include "fan_choice.h"
#include "finish_steps.h"

#include <pcl_ms/mesh_topology.h>

#include <algorithm>
#include <array>
#include <functional>

namespace pcl_ms {
namespace detail {
namespace {

/// The triangles at each marked vertex, those marked `gone` left out: one
/// scan of the mesh, and memory for the marked vertices only (a few, or a
/// seam's, of a large mesh).
class MarkedIncidence {
public:
  MarkedIncidence(const std::vector<Triangle> &triangles, const std::vector<bool> &marked,
                  const std::vector<bool> &gone) {
    for (VertexIndex v = 0; v < marked.size(); ++v)
      if (marked[v])
        vertices_.push_back(v);
    at_.resize(vertices_.size());
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      if (!gone[t])
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

} // namespace

void dropBowTieFans(VertexIndex v, const std::vector<std::uint32_t> &around,
                    const std::vector<Triangle> &triangles,
                    const std::function<bool(std::uint32_t)> &is_fixed,
                    std::vector<std::uint32_t> &drop) {
  if (around.size() < 2)
    return;
  const auto fans = fansAt(v, around, triangles);
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
    std::vector<std::uint32_t> drop;
    for (std::size_t slot = 0; slot < incidence.vertices().size(); ++slot)
      dropBowTieFans(incidence.vertices()[slot], incidence.atSlot(slot), triangles, isFixed, drop);
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
