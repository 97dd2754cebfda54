// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 3's opt-in seams (docs/algorithm.md section 4a). In: the scaffold's
// candidates before the passes, the 2-manifold mesh after them. Out: likely
// seam edges and the candidates bridging them (left out of the passes), then
// the seam pass's triangles and the mesh's triangles set apart at seams.
#include "greedy_impl.h"

#include <pcl_ms/costs.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>
#include <unordered_map>

namespace pcl_ms {
namespace {

using detail::SeamAxis;

// Seam pass (docs/algorithm.md, "Seams (opt-in)"): a triangle joins a likely
// seam edge that holds two already only in a sheet of that edge (found
// before the passes) that no triangle there occupies yet.
// Sheets: a point is in a sheet of a seam edge when its direction around the
// edge is within this (about 29 degrees) of the sheet's, two neighbouring
// seam edges have the same sheets when these agree within it, and the third
// sheet grows from a rim whose triangles lie within it of its plane.
constexpr double max_sheet_bending = 0.5;
// Across an edge with one triangle, a seam-pass triangle may bend up to
// this much (about 92 degrees): where a seam ends at a box corner, the
// third sheet's triangle meets the box's crease. Triangles bridging two
// sheets are left out by seam detection instead.
constexpr double max_attached_bending = 1.6;
// A seam triangle's longest side is at most this times the longest side of
// the triangles on its full edge: on the test clouds the right ones measured
// 0.78-1.14 times, triangles bridging the wedge between two sheets 1.6-2.2.
constexpr double max_seam_size_ratio = 1.4;
// Seam detection (docs/algorithm.md, "Seams (opt-in)"): around an edge, the
// apexes of its Gabriel candidates fall into groups (sheets) separated by
// gaps of at least this much (about 34 degrees); three or more groups make
// the edge a likely seam edge.
constexpr double min_sheet_gap = 0.6;
// A point is along a seam edge's axis (in no sheet in particular) when its
// direction from the seam vertex is within this angle of the axis.
constexpr double max_axis_angle = 0.35;
// A group is a sheet when its cheapest candidate costs at most this times
// the cheapest around the edge: on the test clouds the sheets' cheapest
// measured within 1.9 times of each other, groups of triangles bridging two
// sheets or reaching across a thin part 2.4 times and far more.
constexpr double max_sheet_cost_ratio = 2.5;
// Seams are curves: a likely seam edge is kept when it is in a chain of at
// least this many, each continuing the next within about 37 degrees
// (cosine 0.8) with the same sheets. On the manifold test surfaces (bunny,
// camel, camel head, fandisk, anchor, noisy sphere) such chains of three
// sheets were 4 edges long at most (across creases, where a fold gives a
// third group); the test seams are chains of 20 and 52.
constexpr std::size_t min_seam_chain = 6;
constexpr double min_chain_cosine = 0.8;

/// The sheet of `seam` within half the smallest gap between sheets (and
/// max_sheet_bending) of `angle`, or -1 (also for NaN: along the axis).
int sheetAt(const SeamAxis &seam, double angle) {
  const std::size_t n = seam.sheets.size();
  double tolerance = M_PI;
  for (std::size_t i = 0; i < n; ++i) {
    double gap = seam.sheets[(i + 1) % n] - seam.sheets[i];
    if (gap <= 0)
      gap += 2 * M_PI;
    tolerance = std::min(tolerance, gap / 2);
  }
  tolerance = std::min(tolerance, max_sheet_bending);
  for (std::size_t i = 0; i < n; ++i) {
    const double difference = std::remainder(angle - seam.sheets[i], 2 * M_PI);
    if (std::abs(difference) <= tolerance)
      return static_cast<int>(i);
  }
  return -1;
}

Eigen::Vector3d sheetDirection(const SeamAxis &seam, double angle) {
  return std::cos(angle) * seam.across1 + std::sin(angle) * seam.across2;
}

/// Whether two neighbouring likely seam edges have the same sheets: as
/// many, each within max_sheet_bending of one of the other's.
bool sameSheets(const SeamAxis &a, const SeamAxis &b) {
  if (a.sheets.size() != b.sheets.size())
    return false;
  for (double angle : a.sheets) {
    const Eigen::Vector3d direction = sheetDirection(a, angle);
    bool matched = false;
    for (double other : b.sheets)
      matched |= direction.dot(sheetDirection(b, other)) >= std::cos(max_sheet_bending);
    if (!matched)
      return false;
  }
  return true;
}

} // namespace

/// The angle of point p around edge `seam`, seen from its vertex v; or
/// nothing (NaN) when p lies along the axis.
double GreedyMesher::Impl::angleAround(const SeamAxis &seam, VertexIndex v, VertexIndex p) const {
  const Eigen::Vector3d offset = points_[p] - points_[v];
  const double along = offset.dot(seam.axis);
  const Eigen::Vector3d across = offset - along * seam.axis;
  if (across.norm() <= std::tan(max_axis_angle) * std::abs(along))
    return std::numeric_limits<double>::quiet_NaN();
  return std::atan2(across.dot(seam.across2), across.dot(seam.across1));
}

/// Before the passes (docs/algorithm.md, "Seams (opt-in)"): the scaffold
/// edges whose Gabriel candidates fan out into three or more sheets, and
/// the candidates that would bridge the wedge between two sheets at one
/// of their ends: those are left out of every pass.
void GreedyMesher::Impl::detectSeams() {
  std::vector<std::pair<double, CandidateIndex>> angles;
  std::vector<EdgeIndex> found; // ascending
  for (EdgeIndex e = 0; e < scaffold_.numberOfEdges(); ++e) {
    const CandidateIndex *begin = scaffold_.edgeBegin(e), *end = scaffold_.edgeEnd(e);
    if (end - begin < 3)
      continue;
    SeamAxis seam;
    VertexIndex high = 0;
    {
      const Candidate &first = candidates_[*begin];
      for (int k = 0; k < 3; ++k)
        if (first.edges[k] == e) {
          seam.low = std::min(first.vertices[k], first.vertices[(k + 1) % 3]);
          high = std::max(first.vertices[k], first.vertices[(k + 1) % 3]);
        }
    }
    seam.axis = (points_[high] - points_[seam.low]).normalized();
    seam.across1 = seam.axis.unitOrthogonal();
    seam.across2 = seam.axis.cross(seam.across1);
    angles.clear();
    for (const CandidateIndex *s = begin; s != end; ++s) {
      if (candidates_[*s].type == CandidateType::ambiguous)
        continue;
      const Eigen::Vector3d offset = points_[apexOf(*s, seam.low, high)] - points_[seam.low];
      angles.emplace_back(std::atan2(offset.dot(seam.across2), offset.dot(seam.across1)), *s);
    }
    if (angles.size() < 3)
      continue;
    std::sort(angles.begin(), angles.end());
    // Groups: runs of angles with gaps below min_sheet_gap, cyclically;
    // each sheet's direction is its group's mean.
    std::size_t start = 0; // a group starts after the largest gap
    double widest = 0;
    for (std::size_t i = 0; i < angles.size(); ++i) {
      double gap = angles[i].first - angles[(i + angles.size() - 1) % angles.size()].first;
      if (gap <= 0)
        gap += 2 * M_PI;
      if (gap > widest) {
        widest = gap;
        start = i;
      }
    }
    if (widest < min_sheet_gap)
      continue;
    double sum = 0, previous = 0;
    float cheapest = std::numeric_limits<float>::max();
    std::size_t members = 0;
    for (std::size_t j = 0; j < angles.size(); ++j) {
      const std::size_t i = (start + j) % angles.size();
      const double angle = angles[i].first + (i < start ? 2 * M_PI : 0.0);
      if (members > 0 && angle - previous >= min_sheet_gap) {
        seam.sheets.push_back(std::remainder(sum / static_cast<double>(members), 2 * M_PI));
        seam.costs.push_back(cheapest);
        sum = 0;
        members = 0;
        cheapest = std::numeric_limits<float>::max();
      }
      cheapest = std::min(cheapest, candidates_[angles[i].second].base_cost);
      sum += angle;
      ++members;
      previous = angle;
    }
    seam.sheets.push_back(std::remainder(sum / static_cast<double>(members), 2 * M_PI));
    seam.costs.push_back(cheapest);
    // Only groups with a cheap candidate are sheets.
    const float cheapest_all = *std::min_element(seam.costs.begin(), seam.costs.end());
    std::vector<double> sheets;
    for (std::size_t i = 0; i < seam.sheets.size(); ++i)
      if (seam.costs[i] <= max_sheet_cost_ratio * cheapest_all)
        sheets.push_back(seam.sheets[i]);
    if (sheets.size() < 3)
      continue;
    seam.sheets = std::move(sheets);
    seam.high = high;
    found.push_back(e);
    seam_axes_.emplace(e, std::move(seam));
  }
  keepSeamChains(found);
  if (seam_axes_.empty())
    return;
  bridges_seam_.assign(candidates_.size(), false);
  for (CandidateIndex t = 0; t < candidates_.size(); ++t)
    bridges_seam_[t] = !is_fixed_[t] && !is_preferred_[t] && bridgesSeam(t);
}

/// Keeps the likely seam edges (`found`, ascending) that form chains of
/// min_seam_chain or more, and lists them at their ends.
void GreedyMesher::Impl::keepSeamChains(const std::vector<EdgeIndex> &found) {
  std::unordered_map<VertexIndex, std::vector<std::uint32_t>> at; // positions in found
  for (std::uint32_t i = 0; i < found.size(); ++i) {
    const SeamAxis &seam = seam_axes_.at(found[i]);
    at[seam.low].push_back(i);
    at[seam.high].push_back(i);
  }
  std::vector<std::uint32_t> parent(found.size());
  std::iota(parent.begin(), parent.end(), 0u);
  const auto root = [&](std::uint32_t i) {
    while (parent[i] != i)
      i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const auto &[v, edges] : at)
    for (std::size_t i = 0; i < edges.size(); ++i)
      for (std::size_t j = i + 1; j < edges.size(); ++j) {
        const SeamAxis &a = seam_axes_.at(found[edges[i]]), &b = seam_axes_.at(found[edges[j]]);
        // Axes run from low to high: away from v, one of them is reversed.
        const double sign = (a.low == v) == (b.low == v) ? 1.0 : -1.0;
        if (sign * a.axis.dot(b.axis) <= -min_chain_cosine && sameSheets(a, b))
          parent[root(edges[i])] = root(edges[j]);
      }
  std::vector<std::size_t> size(found.size(), 0);
  for (std::uint32_t i = 0; i < found.size(); ++i)
    ++size[root(i)];
  for (std::uint32_t i = 0; i < found.size(); ++i) {
    if (size[root(i)] < min_seam_chain) {
      seam_axes_.erase(found[i]);
      continue;
    }
    const SeamAxis &seam = seam_axes_.at(found[i]);
    seams_at_[seam.low].push_back(found[i]);
    seams_at_[seam.high].push_back(found[i]);
  }
}

/// Whether t, at one of its corners on a likely seam edge, reaches from
/// one sheet to another (or off all of them) for every seam edge there.
bool GreedyMesher::Impl::bridgesSeam(CandidateIndex t) const {
  const Triangle &corners = candidates_[t].vertices;
  for (int k = 0; k < 3; ++k) {
    const auto found = seams_at_.find(corners[k]);
    if (found == seams_at_.end())
      continue;
    const VertexIndex v = corners[k], a = corners[(k + 1) % 3], b = corners[(k + 2) % 3];
    bool fits_one = false;
    for (EdgeIndex e : found->second) {
      const SeamAxis &seam = seam_axes_.at(e);
      const double angle_a = angleAround(seam, v, a), angle_b = angleAround(seam, v, b);
      const int sheet_a = std::isnan(angle_a) ? -2 : sheetAt(seam, angle_a);
      const int sheet_b = std::isnan(angle_b) ? -2 : sheetAt(seam, angle_b);
      if (sheet_a == -1 || sheet_b == -1)
        continue;
      if (sheet_a == -2 || sheet_b == -2 || sheet_a == sheet_b) {
        fits_one = true;
        break;
      }
    }
    if (!fits_one)
      return true;
  }
  return false;
}

/// Whether t may join in the seam pass: as a *seam* triangle, on one or
/// two likely seam edges that hold two or more triangles, in a sheet of
/// each that is still free, and attached to a sheet (an edge with one
/// triangle, or its apex on a sheet's rim along that sheet: the third
/// sheet grows from its rim); or as a *filler* that closes the gap between
/// a seam triangle and a sheet (two edges with one triangle each, one of
/// them a seam triangle's). It must not bridge a seam, and across edges
/// with one triangle it bends at most max_attached_bending.
GreedyMesher::Impl::SeamFit GreedyMesher::Impl::seamFit(CandidateIndex t) const {
  const Candidate &candidate = candidates_[t];
  // Only Gabriel triangles (types I, II): type III ones bridged the wedge
  // between sheets on the test clouds.
  if (mesh_.contains(t) || is_seam_[t] || candidate.type == CandidateType::ambiguous ||
      bridges_seam_.empty() || bridges_seam_[t])
    return SeamFit::none;
  int full = 0, attached = 0, full_slot = 0;
  bool next_to_seam_triangle = false;
  for (int k = 0; k < 3; ++k) {
    const EdgeIndex e = candidate.edges[k];
    const std::size_t uses = edgeUses(e);
    const VertexIndex p = candidate.vertices[k], q = candidate.vertices[(k + 1) % 3];
    const VertexIndex apex = candidate.vertices[(k + 2) % 3];
    bool fits = true;
    if (uses >= 2) {
      // On a likely seam edge, one triangle per sheet: t's apex must lie
      // in a sheet that none of the triangles there occupies.
      const auto seam = seam_axes_.find(e);
      if (seam == seam_axes_.end())
        return SeamFit::none;
      const VertexIndex low = seam->second.low;
      const int sheet = sheetAt(seam->second, angleAround(seam->second, low, apex));
      fits = sheet >= 0;
      forEachOccupant(e, [&](CandidateIndex u) {
        fits &= sheetAt(seam->second, angleAround(seam->second, low, apexOf(u, p, q))) != sheet;
        next_to_seam_triangle |= is_seam_[u];
      });
    } else {
      forEachOccupant(e, [&](CandidateIndex u) {
        fits &= bendingAngle(points_[p], points_[q], points_[apex], points_[apexOf(u, p, q)]) <=
                max_attached_bending;
        next_to_seam_triangle |= is_seam_[u];
      });
    }
    if (!fits)
      return SeamFit::none;
    if (uses >= 2) {
      ++full;
      full_slot = k;
    }
    attached += uses == 1;
  }
  // On each full edge (a likely seam edge: checked above) up to one
  // triangle per sheet, and no larger than the triangles there. Two full
  // edges: a corner where the seam turns, attached to its sheet.
  for (int k = 0; k < 3; ++k) {
    const EdgeIndex e = candidate.edges[k];
    if (edgeUses(e) < 2)
      continue;
    if (edgeUses(e) >= seam_axes_.at(e).sheets.size() ||
        longestSide(t) > max_seam_size_ratio * longestOnEdge(e))
      return SeamFit::none;
  }
  if (full == 2)
    return attached > 0 ? SeamFit::seam : SeamFit::none;
  if (full == 1)
    return attached > 0 || continuesSheetAt(t, candidate.vertices[(full_slot + 2) % 3])
               ? SeamFit::seam
               : SeamFit::none;
  return attached >= 2 && next_to_seam_triangle ? SeamFit::filler : SeamFit::none;
}

double GreedyMesher::Impl::longestSide(CandidateIndex t) const {
  const auto &v = candidates_[t].vertices;
  return std::sqrt(std::max({(points_[v[0]] - points_[v[1]]).squaredNorm(),
                             (points_[v[1]] - points_[v[2]]).squaredNorm(),
                             (points_[v[2]] - points_[v[0]]).squaredNorm()}));
}

/// The longest side among the triangles on edge e.
double GreedyMesher::Impl::longestOnEdge(EdgeIndex e) const {
  double longest = 0;
  forEachOccupant(e, [&](CandidateIndex u) { longest = std::max(longest, longestSide(u)); });
  return longest;
}

/// Whether t lies along a sheet whose rim passes through its corner v: v
/// is on a boundary edge of the mesh and one of its triangles is within
/// max_sheet_bending of t's plane.
bool GreedyMesher::Impl::continuesSheetAt(CandidateIndex t, VertexIndex v) const {
  if (mesh_.vertexBoundaryEdges(v) == 0)
    return false;
  const auto normal = [&](const Triangle &corners) {
    return (points_[corners[1]] - points_[corners[0]])
        .cross(points_[corners[2]] - points_[corners[0]])
        .normalized();
  };
  const Eigen::Vector3d own = normal(candidates_[t].vertices);
  for (CandidateIndex u : mesh_.vertexTriangles(v))
    if (std::abs(own.dot(normal(candidates_[u].vertices))) >= std::cos(max_sheet_bending))
      return true;
  return false;
}

/// Base cost plus the context of every triangle already on t's edges.
float GreedyMesher::Impl::seamCost(CandidateIndex t) const {
  double context = 0;
  for (EdgeIndex e : candidates_[t].edges)
    forEachOccupant(e, [&](CandidateIndex u) {
      for (int k = 0; k < 3; ++k)
        if (candidates_[u].edges[k] == e)
          context += contextTerm(u, k, t);
    });
  return static_cast<float>(std::max(0.0, candidates_[t].base_cost + context));
}

/// The third queue (paper Fig. 18): after pass 2 and the manifold sweep,
/// candidates that fit (seamFit) are accepted cheapest first; each one
/// accepted brings the candidates at its corners in again.
void GreedyMesher::Impl::runSeamPass() {
  const std::size_t count = candidates_.size();
  is_seam_.assign(count, false);
  // Candidates by corner, to find those a new seam triangle affects: the
  // Gabriel ones (seamFit), which all have their edges numbered.
  auto listed = [&](CandidateIndex t) {
    return !mesh_.contains(t) && candidates_[t].type != CandidateType::ambiguous;
  };
  std::vector<std::uint32_t> offsets(points_.size() + 1, 0);
  for (CandidateIndex t = 0; t < count; ++t)
    if (listed(t))
      for (VertexIndex v : candidates_[t].vertices)
        ++offsets[v + 1];
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  std::vector<CandidateIndex> at_vertex(offsets.back());
  std::vector<std::uint32_t> cursor(offsets.begin(), offsets.end() - 1);
  for (CandidateIndex t = 0; t < count; ++t)
    if (listed(t))
      for (VertexIndex v : candidates_[t].vertices)
        at_vertex[cursor[v]++] = t;

  using Entry = std::pair<float, CandidateIndex>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  for (CandidateIndex t = 0; t < count; ++t)
    if (listed(t) && seamFit(t) != SeamFit::none)
      heap.emplace(seamCost(t), t);
  while (!heap.empty()) {
    const auto [cost, t] = heap.top();
    heap.pop();
    if (deadline_)
      deadline_->checkEvery(deadline_counter_, "the seam pass");
    if (is_seam_[t] || seamFit(t) == SeamFit::none)
      continue;
    const float current = seamCost(t);
    if (current != cost) { // its context changed since it was queued
      heap.emplace(current, t);
      continue;
    }
    is_seam_[t] = true;
    seam_list_.push_back(t);
    ++statistics_.seam_triangles;
    for (EdgeIndex e : candidates_[t].edges)
      seam_on_edge_[e].push_back(t);
    for (VertexIndex v : candidates_[t].vertices)
      for (std::uint32_t i = offsets[v]; i < offsets[v + 1]; ++i)
        if (seamFit(at_vertex[i]) != SeamFit::none)
          heap.emplace(seamCost(at_vertex[i]), at_vertex[i]);
  }
}

/// After the seam pass: the mesh's triangles on edges that now hold three
/// or more join the seam triangles, so that the finish sees each sheet
/// ending at the seam rather than two sheets joined across it (orienting
/// those twisted them; docs/algorithm.md, "Seams (opt-in)").
void GreedyMesher::Impl::setSeamFansApart() {
  if (seam_list_.empty())
    return;
  is_set_apart_.assign(candidates_.size(), false);
  for (CandidateIndex t = 0; t < candidates_.size(); ++t) {
    if (!mesh_.contains(t) || is_fixed_[t])
      continue;
    for (EdgeIndex e : candidates_[t].edges)
      if (edgeUses(e) >= 3) {
        is_set_apart_[t] = true;
        set_apart_.push_back(t);
        break;
      }
  }
}
} // namespace pcl_ms
