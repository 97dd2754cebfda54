// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4, orientation and twists (docs/algorithm.md section 4,
// "Orientation", "Twists"). In: a triangle list, its manifold pairs and the
// points (and a viewpoint, if any). Out: each component oriented, which
// components are orientable, and the triangles to cut where a twist is a fold.
#include "finish_steps.h"

#include <pcl_ms/costs.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace pcl_ms {
namespace detail {
namespace {

// An inconsistent edge that bends by more than this (90 degrees) is a fold,
// cut whatever its twist: a crumpled spot, never the gentle twist of a real
// Moebius band, which is kept and reported.
constexpr double max_untwist_bending = M_PI / 2;
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

/// Whether triangle t, as stored, runs from a to b.
bool runsFromTo(const Triangle &t, VertexIndex a, VertexIndex b) {
  for (int k = 0; k < 3; ++k)
    if (t[k] == a && t[(k + 1) % 3] == b)
      return true;
  return false;
}

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

double bendingAt(const ManifoldPair &pair, const std::vector<Triangle> &triangles,
                 const std::vector<Eigen::Vector3d> &points) {
  const Triangle &first = triangles[pair.first], &second = triangles[pair.second];
  auto inSecond = [&](VertexIndex v) { return v == second[0] || v == second[1] || v == second[2]; };
  // The shared edge, lower vertex first, and each triangle's third vertex.
  VertexIndex shared[2] = {0, 0}, first_apex = first[0];
  int found = 0;
  for (VertexIndex v : first)
    if (inSecond(v) && found < 2)
      shared[found++] = v;
    else
      first_apex = v;
  const VertexIndex a = std::min(shared[0], shared[1]), b = std::max(shared[0], shared[1]);
  VertexIndex second_apex = second[0];
  for (VertexIndex v : second)
    if (v != a && v != b)
      second_apex = v;
  return bendingAngle(points[a], points[b], points[first_apex], points[second_apex]);
}

/// The manifold pairs of each triangle, in pair order: at most three, one
/// per edge, so three slots a triangle and no offsets (12 bytes a triangle).
class PairsOfTriangles {
public:
  static constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();

  PairsOfTriangles(const std::vector<ManifoldPair> &pairs, std::size_t triangle_count)
      : slots_(3 * triangle_count, none) {
    for (std::uint32_t p = 0; p < pairs.size(); ++p)
      for (std::uint32_t t : {pairs[p].first, pairs[p].second})
        for (std::size_t k = 3 * std::size_t{t};; ++k)
          if (slots_[k] == none) { // a triangle has at most 3 edges, so a free slot
            slots_[k] = p;
            break;
          }
  }

  /// Triangle t's pairs.
  struct Range {
    const std::uint32_t *begin_, *end_;
    const std::uint32_t *begin() const { return begin_; }
    const std::uint32_t *end() const { return end_; }
    std::size_t size() const { return static_cast<std::size_t>(end_ - begin_); }
  };
  Range of(std::uint32_t t) const {
    const std::uint32_t *first = &slots_[3 * std::size_t{t}];
    return {first, std::find(first, first + 3, none)};
  }

private:
  std::vector<std::uint32_t> slots_;
};

/// Whether t and u run their shared edge in opposite directions.
bool consistentlyOriented(const Triangle &t, const Triangle &u) {
  for (int k = 0; k < 3; ++k)
    if (runsFromTo(u, t[(k + 1) % 3], t[k]))
      return true;
  return false;
}

/// Whether a walk of at most max_steps triangles from `start` across
/// manifold pairs returns to it with its orientation reversed (crossing a
/// pair flagged in `flips` reverses it): breadth first over (triangle,
/// reversed) states. `reached` has one entry per triangle, all 0 (bit 0:
/// reached as it is, bit 1: reversed), and is left so.
bool reversesWithin(std::uint32_t start, int max_steps, const std::vector<ManifoldPair> &pairs,
                    const PairsOfTriangles &incident, const std::vector<std::uint8_t> &flips,
                    std::vector<std::uint8_t> &reached) {
  using State = std::pair<std::uint32_t, bool>;
  std::vector<State> frontier = {{start, false}}, next;
  std::vector<std::uint32_t> touched = {start};
  reached[start] = 1;
  bool reverses = false;
  for (int step = 0; step < max_steps && !frontier.empty() && !reverses; ++step) {
    next.clear();
    for (const auto &[t, reversed] : frontier)
      for (std::uint32_t p : incident.of(t)) {
        if (reverses)
          break;
        const ManifoldPair &pair = pairs[p];
        const State state{pair.first == t ? pair.second : pair.first, reversed != (flips[p] != 0)};
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

} // namespace

std::vector<std::uint32_t> orientPairs(std::vector<Triangle> &triangles,
                                       const std::vector<ManifoldPair> &pairs,
                                       const std::vector<Eigen::Vector3d> &points,
                                       std::vector<std::uint32_t> &triangle_component,
                                       std::vector<bool> &component_orientable,
                                       const Eigen::Vector3d *viewpoint) {
  const std::uint32_t unvisited = std::numeric_limits<std::uint32_t>::max();
  const PairsOfTriangles incident(pairs, triangles.size());
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
      for (std::uint32_t p : incident.of(t)) {
        const ManifoldPair &pair = pairs[p];
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
    // Kruskal's forest after the flat pairs does not depend on their order
    // when no cycle of flat pairs is twisted: the same triangles end up
    // together with the same relative flips. So they are joined unsorted, as
    // met, and only the few bent pairs are kept and sorted; the bending is
    // computed a block of pairs at a time, never stored for them all (at 10M
    // points that was 240 MB). A twist among flat pairs needs Kruskal's
    // order throughout.
    ParityForest forest(triangles.size());
    // Flipping exactly one of a pair changes whether the two agree.
    auto join = [&](std::uint32_t p) {
      return forest.join(pairs[p].first, pairs[p].second, inconsistent[p]);
    };
    struct BentPair {
      double bending;
      std::uint32_t pair;
    };
    std::vector<BentPair> bent_pairs;
    // Calls take(p, bending) for each pair of a twisted component, in order.
    auto forEachTwistedPair = [&](const auto &take) {
      constexpr std::size_t block = std::size_t(1) << 20;
      std::vector<double> bending;
      for (std::size_t first = 0; first < pairs.size(); first += block) {
        const std::size_t count = std::min(block, pairs.size() - first);
        bending.assign(count, 0.0);
        forEachIndex(count, [&](std::size_t i) {
          if (inTwistedComponent(first + i))
            bending[i] = bendingAt(pairs[first + i], triangles, points);
        });
        for (std::size_t i = 0; i < count; ++i)
          if (inTwistedComponent(first + i))
            take(static_cast<std::uint32_t>(first + i), bending[i]);
      }
    };
    bool flat_cycle_twisted = false;
    forEachTwistedPair([&](std::uint32_t p, double bending) {
      if (bending < kruskal_flat_bending)
        flat_cycle_twisted |= join(p) == ParityForest::Join::conflict;
      else
        bent_pairs.push_back({bending, p});
    });
    if (flat_cycle_twisted) {
      forest = ParityForest(triangles.size());
      bent_pairs.clear();
      forEachTwistedPair([&](std::uint32_t p, double bending) {
        bent_pairs.push_back({bending, p});
      });
    }
    std::sort(bent_pairs.begin(), bent_pairs.end(), [](const BentPair &a, const BentPair &b) {
      return a.bending < b.bending || (a.bending == b.bending && a.pair < b.pair);
    });
    // A pair that closes a cycle leaves the forest as it is, consistent or not.
    for (const BentPair &bent : bent_pairs)
      join(bent.pair);
    std::vector<BentPair>().swap(bent_pairs);
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      if (!component_orientable[triangle_component[t]] && forest.find(t).second)
        std::swap(triangles[t][1], triangles[t][2]);
    forest = ParityForest(0);

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
        if (reversesWithin(pairs[p].first, max_local_twist_steps, pairs, incident, conflict,
                           reached))
          return true;
        if (holds_real_twist[component] || long_walk <= max_local_twist_steps)
          return false;
        if (reversesWithin(pairs[p].first, long_walk, pairs, incident, conflict, reached))
          return true;
        holds_real_twist[component] = true;
        return false;
      };
      if (viewpoint)
        to_cut.push_back(moreEdgeOn(pairs[p]));
      else if (bendingAt(pairs[p], triangles, points) > max_untwist_bending || localTwist()) {
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
      closed = closed && incident.of(t).size() == 3;
    }
    if ((viewpoint && !closed ? facing : signed_volume) < 0)
      for (std::uint32_t t : members[component])
        std::swap(triangles[t][1], triangles[t][2]);
  }
  return to_cut;
}

} // namespace detail

std::vector<std::uint32_t> orientComponents(std::vector<Triangle> &triangles,
                                            const std::vector<Eigen::Vector3d> &points,
                                            std::vector<std::uint32_t> &triangle_component,
                                            std::vector<bool> &component_orientable,
                                            const Eigen::Vector3d *viewpoint) {
  return detail::orientPairs(triangles, detail::meshEdges(triangles, true).pairs, points,
                             triangle_component, component_orientable, viewpoint);
}

} // namespace pcl_ms
