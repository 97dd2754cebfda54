// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 3's repairs after pass 2 (docs/algorithm.md section 3). In: the mesh
// the passes accepted. Out: the same with non-Delaunay quads swapped for the
// other diagonal where that bends the surface no more, and one fan per vertex
// (the manifold sweep).
#include "fan_choice.h"
#include "greedy_impl.h"

#include <pcl_ms/costs.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace pcl_ms {
namespace {

// A swap must improve the angle sum by more than rounding noise, or
// co-circular quads would flip back and forth.
constexpr double swap_angle_tolerance = 1e-9;

// Swaps may bend a quad up to this much (20 degrees) even when it was flatter
// before: smooth surfaces bend a little either way.
constexpr double smooth_bending_angle = 0.35;
// The swap pass reads its edges in list order, but their records lie all
// over memory: it fetches them in stages this many steps apart.
constexpr std::size_t swap_prefetch_step = 4;

} // namespace

/// The edge of candidate t joining a and b (both vertices of t).
EdgeIndex GreedyMesher::Impl::edgeBetween(CandidateIndex t, VertexIndex a, VertexIndex b) const {
  const Candidate &candidate = candidates_[t];
  for (int k = 0; k < 3; ++k) {
    const VertexIndex p = candidate.vertices[k], q = candidate.vertices[(k + 1) % 3];
    if ((p == a && q == b) || (p == b && q == a))
      return candidate.edges[k];
  }
  // Callers pass two corners of t; anything else is a broken invariant,
  // which must stop the run rather than quietly use some edge.
  throw std::logic_error("GreedyMesher: vertices " + std::to_string(a) + " and " +
                         std::to_string(b) + " are not an edge of candidate " + std::to_string(t));
}

/// The candidate (a, b, apex), where a and b are the ends of edge e, or
/// no_candidate: on e's lists, else among the type III candidates without
/// edges. Vertex sets are unique, so where it is found does not matter.
CandidateIndex GreedyMesher::Impl::candidateWith(EdgeIndex e, VertexIndex a, VertexIndex b,
                                                 VertexIndex apex) const {
  CandidateIndex found = no_candidate;
  forEachCandidateOn(e, [&](CandidateIndex s) {
    const auto &v = candidates_[s].vertices;
    if (v[0] == apex || v[1] == apex || v[2] == apex)
      found = s;
    return found != no_candidate;
  });
  if (found != no_candidate)
    return found;
  Triangle vertices = {a, b, apex};
  std::sort(vertices.begin(), vertices.end());
  return graph_.unnumberedWith(vertices);
}

/// Whether the angles at b and d opposite edge ac sum to more than pi
/// (plus the tolerance): the sine of the sum is negative then. Sines and
/// cosines come from cross and dot products, without any arctangent.
bool GreedyMesher::Impl::oppositeAnglesExceedPi(VertexIndex b, VertexIndex d, VertexIndex a,
                                                VertexIndex c) const {
  const Eigen::Vector3d ub = points_[a] - points_[b], wb = points_[c] - points_[b];
  const Eigen::Vector3d ud = points_[a] - points_[d], wd = points_[c] - points_[d];
  const double sine_b = ub.cross(wb).norm(), sine_d = ud.cross(wd).norm();
  const double scale =
      std::sqrt(ub.squaredNorm() * wb.squaredNorm() * ud.squaredNorm() * wd.squaredNorm());
  return sine_b * ud.dot(wd) + ub.dot(wb) * sine_d < -swap_angle_tolerance * scale;
}

/// Error recovery after the passes: two accepted triangles (a, c, b) and
/// (a, c, d) whose quad is not locally Delaunay on the surface (the angles
/// at b and d sum to more than pi) are replaced by the other pair of
/// Delaunay candidates (a, b, d), (b, c, d), when that pair exists, its
/// diagonal is not a mesh edge yet and it bends the surface no more (so
/// ridges stay). On curved surfaces the 3-D empty-sphere test alone often
/// picks the diagonal a surface triangulation would not.
void GreedyMesher::Impl::swapNonDelaunayDiagonals() {
  graph_.listUnnumbered(points_.size());
  std::vector<EdgeIndex> work;
  std::vector<bool> queued(edgeCount(), false);
  auto enqueue = [&](EdgeIndex e) {
    if (e >= queued.size()) // numbered by a swap
      queued.resize(edgeCount(), false);
    if (!queued[e] && mesh_.edgeTriangleCount(e) == 2) {
      queued[e] = true;
      work.push_back(e);
    }
  };
  for (CandidateIndex t = 0; t < candidates_.size(); ++t) {
    const CandidateIndex ahead = t + 2 * swap_prefetch_step;
    if (ahead < candidates_.size() && mesh_.contains(ahead))
      for (EdgeIndex e : candidates_[ahead].edges)
        __builtin_prefetch(&mesh_.edgeTriangles(e));
    if (mesh_.contains(t))
      for (EdgeIndex e : candidates_[t].edges)
        enqueue(e);
  }
  // Flips on a curved surface change its geometry, so unlike in the plane
  // termination is not guaranteed: bound the work.
  std::size_t budget = 4 * work.size() + 16;
  for (std::size_t head = 0; head < work.size() && budget > 0; ++head, --budget) {
    // Ahead along the list: an edge's slots, then its triangles' records,
    // then their corners' positions, each fetched once the one before is in.
    if (head + 3 * swap_prefetch_step < work.size())
      __builtin_prefetch(&mesh_.edgeTriangles(work[head + 3 * swap_prefetch_step]));
    if (head + 2 * swap_prefetch_step < work.size())
      for (CandidateIndex u : mesh_.edgeTriangles(work[head + 2 * swap_prefetch_step]))
        if (u != no_candidate)
          __builtin_prefetch(&candidates_[u]);
    if (head + swap_prefetch_step < work.size())
      for (CandidateIndex u : mesh_.edgeTriangles(work[head + swap_prefetch_step]))
        if (u != no_candidate)
          for (VertexIndex v : candidates_[u].vertices)
            __builtin_prefetch(&points_[v]);
    const EdgeIndex e = work[head];
    queued[e] = false;
    if (mesh_.edgeTriangleCount(e) != 2)
      continue;
    const auto [first, second] = mesh_.edgeTriangles(e);
    if (is_fixed_[first] || is_fixed_[second] || is_preferred_[first] || is_preferred_[second])
      continue;
    if (seam_axes_.count(e)) // a likely seam edge stays (docs/algorithm.md, "Seams")
      continue;
    VertexIndex a = 0, c = 0;
    for (int k = 0; k < 3; ++k)
      if (candidates_[first].edges[k] == e) {
        a = candidates_[first].vertices[k];
        c = candidates_[first].vertices[(k + 1) % 3];
      }
    const VertexIndex b = apexOf(first, a, c), d = apexOf(second, a, c);
    if (!oppositeAnglesExceedPi(b, d, a, c))
      continue;
    const CandidateIndex abd = candidateWith(edgeBetween(first, a, b), a, b, d);
    const CandidateIndex bcd = candidateWith(edgeBetween(first, b, c), b, c, d);
    if (abd == no_candidate || bcd == no_candidate || states_[abd].state == State::accepted ||
        states_[bcd].state == State::accepted)
      continue;
    if (!bridges_seam_.empty() && (bridges_seam_[abd] || bridges_seam_[bcd]))
      continue;
    const EdgeIndex diagonal = findEdge(b, d);
    if (diagonal != no_edge && mesh_.edgeTriangleCount(diagonal) != 0)
      continue;
    const double bending_before = bendingAngle(points_[a], points_[c], points_[b], points_[d]);
    const double bending_after = bendingAngle(points_[b], points_[d], points_[a], points_[c]);
    if (bending_after > std::max(bending_before, smooth_bending_angle))
      continue;
    for (CandidateIndex old : {first, second}) {
      removeFromMesh(old);
      states_[old].state = State::dropped;
    }
    for (CandidateIndex replacement : {abd, bcd})
      if (!hasEdges(replacement)) {
        graph_.bringIn(replacement);
        mesh_.growEdges(edgeCount());
      }
    for (CandidateIndex replacement : {abd, bcd}) {
      if (isQueued(replacement)) // its heap entry is outdated from now on
        --queued_[queueNumber(states_[replacement].state)];
      mesh_.add(replacement);
      states_[replacement].state = State::accepted;
      propagateContext(replacement, +1.0);
      for (EdgeIndex outer : candidates_[replacement].edges)
        enqueue(outer);
    }
    ++statistics_.swapped_pairs;
  }
  graph_.forgetUnnumbered();
}

/// Final guarantee: every vertex's triangles form one fan. At a bow-tie the
/// fan chosen by the one bow-tie rule (fan_choice.h) stays and the others are
/// undone, except fixed triangles; removals can split fans at neighbouring
/// vertices, so those are checked again. A vertex gets a second fan only when a
/// triangle at it was removed or accepted against the vertex-face incidence rule: only those
/// vertices are looked at.
void GreedyMesher::Impl::enforceManifoldVertices() {
  std::vector<VertexIndex> pending;
  std::vector<bool> is_pending(points_.size(), false);
  for (VertexIndex v = 0; v < points_.size(); ++v)
    if (may_have_several_fans_[v] && mesh_.vertexTriangleCount(v) > 0) {
      pending.push_back(v);
      is_pending[v] = true;
    }
  while (!pending.empty()) {
    const VertexIndex v = pending.back();
    pending.pop_back();
    is_pending[v] = false;
    if (deadline_)
      deadline_->checkEvery(deadline_counter_, "the manifold sweep");
    if (mesh_.isSingleFan(v))
      continue;
    const auto fans = mesh_.fansAround(v);
    const std::size_t best = detail::fanToKeep(fans.size(), [&](std::size_t f) {
      return detail::FanWeight{fixedCount(fans[f]), preferredCount(fans[f]), fans[f].size(),
                               fanCost(fans[f])};
    });
    for (std::size_t f = 0; f < fans.size(); ++f) {
      if (f == best)
        continue;
      for (CandidateIndex u : fans[f]) {
        if (is_fixed_[u])
          continue;
        removeFromMesh(u);
        states_[u].state = State::dropped;
        ++statistics_.cleanup_undone;
        for (VertexIndex w : candidates_[u].vertices)
          if (w != v && !is_pending[w]) {
            is_pending[w] = true;
            pending.push_back(w);
          }
      }
    }
  }
}

std::size_t GreedyMesher::Impl::fixedCount(const std::vector<CandidateIndex> &fan) const {
  return static_cast<std::size_t>(
      std::count_if(fan.begin(), fan.end(), [&](CandidateIndex u) { return is_fixed_[u]; }));
}

std::size_t GreedyMesher::Impl::preferredCount(const std::vector<CandidateIndex> &fan) const {
  return static_cast<std::size_t>(
      std::count_if(fan.begin(), fan.end(), [&](CandidateIndex u) { return is_preferred_[u]; }));
}

double GreedyMesher::Impl::fanCost(const std::vector<CandidateIndex> &fan) const {
  double total = 0;
  for (CandidateIndex u : fan)
    total += states_[u].cost;
  return total;
}
} // namespace pcl_ms
