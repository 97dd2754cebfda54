// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4, orientation and twists (docs/algorithm.md section 4,
// "Orientation", "Twists"). In: a triangle list, its manifold neighbours and the
// points (and a viewpoint, if any). Out: each component oriented, which
// components are orientable, and the triangles to cut where a twist is a fold.
#include "exact_signs.h"
#include "finish_steps.h"
#include "twist_bending.h"

#include <pcl_ms/costs.h>
#include <pcl_ms/disjoint_sets.h>

#include <algorithm>
#include <cmath>

namespace pcl_ms {
namespace detail {
namespace {

/// Calls measure(p, q, t's apex, u's apex) for the edge pq (p the lower
/// vertex) that t and u share.
template <typename Measure>
auto acrossSharedEdge(std::uint32_t t, std::uint32_t u, const std::vector<Triangle> &triangles,
                      const std::vector<Eigen::Vector3d> &points, const Measure &measure) {
  const EdgeKey edge = sharedEdge(triangles[t], triangles[u]);
  return measure(points[lowVertex(edge)], points[highVertex(edge)],
                 points[triangles[t][apexCorner(triangles[t], edge)]],
                 points[triangles[u][apexCorner(triangles[u], edge)]]);
}

/// How much the surface bends across the edge that t and u share.
double bendingAt(std::uint32_t t, std::uint32_t u, const std::vector<Triangle> &triangles,
                 const std::vector<Eigen::Vector3d> &points) {
  return acrossSharedEdge(t, u, triangles, points,
                          [](const auto &...corners) { return bendingAngle(corners...); });
}

/// kruskalBending() there: 0 where the surface is surely flat.
double kruskalBendingAt(std::uint32_t t, std::uint32_t u, const std::vector<Triangle> &triangles,
                        const std::vector<Eigen::Vector3d> &points) {
  return acrossSharedEdge(t, u, triangles, points,
                          [](const auto &...corners) { return kruskalBending(corners...); });
}

/// Triangle t's manifold neighbours (MeshEdges::neighbours), in the order
/// of the shared edges' keys.
struct Neighbours {
  const std::uint32_t *begin_, *end_;
  const std::uint32_t *begin() const { return begin_; }
  const std::uint32_t *end() const { return end_; }
  std::size_t size() const { return static_cast<std::size_t>(end_ - begin_); }
};
Neighbours neighboursOf(const std::vector<std::uint32_t> &neighbours, std::uint32_t t) {
  const std::uint32_t *first = &neighbours[3 * std::size_t{t}];
  return {first, std::find(first, first + 3, no_neighbour)};
}

/// The manifold edges, each once (from its lower triangle t to u), for
/// joining in a ParityForest of the triangles in parallel. The triangles
/// are cut into ranges by their lowest corner (the points are in spatial
/// order, so most neighbours share a range; by triangle number 40 % of the
/// edges of a 1M-point surface crossed ranges); the edges within a range are
/// joined in parallel, one task per range, whose forest entries point only
/// within it; then the edges between ranges, one by one. A parity forest
/// whose roots are the first triangles ends with the same sets and flips
/// whatever order its joins come in, so the result does not depend on the
/// threads.
class ParallelJoins {
public:
  ParallelJoins(const std::vector<Triangle> &triangles, std::size_t vertex_count,
                const std::vector<std::uint32_t> &neighbours)
      : triangles_(triangles), neighbours_(neighbours),
        shift_(rangeShift(triangles.size(), vertex_count)),
        ranges_(static_cast<std::size_t>((std::max<std::size_t>(vertex_count, 1) - 1) >> shift_) +
                1),
        first_(ranges_ + 1, 0), order_(triangles.size()), between_(ranges_) {
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      ++first_[rangeOf(t) + 1];
    for (std::size_t range = 0; range < ranges_; ++range)
      first_[range + 1] += first_[range];
    std::vector<std::uint32_t> next(first_.begin(), first_.end() - 1);
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      order_[next[rangeOf(t)]++] = t;
    // The few edges between ranges (1 % of a 1M-point surface's), listed
    // once: finding them by a scan of every triangle cost each call as
    // much as joining all the others in parallel.
    parallelFor(std::size_t(0), ranges_, [&](std::size_t range) {
      forEachEdgeOf(range, [&](std::uint32_t t, std::uint32_t u, bool within) {
        if (!within)
          between_[range].emplace_back(t, u);
      });
    });
  }

  /// How many parts forEachEdge() passes: the ranges, then the edges between.
  std::size_t parts() const { return ranges_ + 1; }

  /// Calls join(t, u, part) for every edge.
  template <typename Join> void forEachEdge(const Join &join) const {
    parallelFor(std::size_t(0), ranges_, [&](std::size_t range) {
      forEachEdgeOf(range, [&](std::uint32_t t, std::uint32_t u, bool within) {
        if (within)
          join(t, u, range);
      });
    });
    for (const auto &edges : between_)
      for (const auto &[t, u] : edges)
        join(t, u, ranges_);
  }

private:
  static constexpr std::size_t max_ranges = 64, min_range = std::size_t(1) << 12;

  /// Calls visit(t, u, within) for the edges whose lower triangle t is in
  /// the range, saying whether u is in it too.
  template <typename Visit> void forEachEdgeOf(std::size_t range, const Visit &visit) const {
    for (std::size_t i = first_[range]; i < first_[range + 1]; ++i) {
      const std::uint32_t t = order_[i];
      for (std::uint32_t u : neighboursOf(neighbours_, t))
        if (u > t)
          visit(t, u, rangeOf(u) == range);
    }
  }

  /// Ranges of 2^shift vertices (a shift, not a division: it is taken for
  /// every edge): as few as make at most 64 ranges and, unless the
  /// triangles are few, about 4,096 triangles or more per range.
  static unsigned rangeShift(std::size_t triangle_count, std::size_t vertex_count) {
    const std::size_t wanted =
        std::max<std::size_t>(1, std::min(max_ranges, triangle_count / min_range));
    unsigned shift = 0;
    while ((std::max<std::size_t>(vertex_count, 1) - 1) >> shift >= wanted)
      ++shift;
    return shift;
  }

  std::size_t rangeOf(std::uint32_t t) const {
    const Triangle &corners = triangles_[t];
    return std::min<std::size_t>(std::min({corners[0], corners[1], corners[2]}) >> shift_,
                                 ranges_ - 1);
  }

  const std::vector<Triangle> &triangles_;
  const std::vector<std::uint32_t> &neighbours_;
  unsigned shift_;
  std::size_t ranges_;
  std::vector<std::uint32_t> first_; // the ranges' starts in order_
  std::vector<std::uint32_t> order_; // the triangles, range by range
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> between_; // per range
};

/// Whether a walk of at most max_steps triangles from a triangle across
/// manifold edges returns to it with its orientation reversed (crossing an
/// edge whose triangles disagree reverses it). Breadth first over
/// (triangle, reversed) states, to half that depth: a reversing walk of
/// length L passes a state at depth ceil(L / 2) whose mirror image (the same
/// triangle the other way) is at depth L - ceil(L / 2), so the search stops
/// at a triangle reached both ways at depths adding up to max_steps or less.
/// Keeps its buffers from one search to the next.
class TwistWalk {
public:
  explicit TwistWalk(std::size_t triangle_count) : reached_(triangle_count, 0) {}

  bool reversesWithin(std::uint32_t start, int max_steps, const std::vector<Triangle> &triangles,
                      const std::vector<std::uint32_t> &neighbours) {
    frontier_.assign(1, {start, false});
    touched_.assign(1, start);
    reached_[start] = as_it_is; // at depth 0
    bool reverses = false;
    const int half = (max_steps + 1) / 2;
    for (int step = 0; step < half && !frontier_.empty() && !reverses; ++step) {
      const std::uint32_t depth = static_cast<std::uint32_t>(step) + 1;
      next_.clear();
      for (const auto &[t, reversed] : frontier_) {
        for (std::uint32_t u : neighboursOf(neighbours, t)) {
          const bool u_reversed = reversed == consistentlyOriented(triangles[t], triangles[u]);
          const std::uint32_t way = u_reversed ? the_other_way : as_it_is;
          std::uint32_t &entry = reached_[u];
          if (entry & way)
            continue;
          if (entry == 0) {
            touched_.push_back(u);
            entry = depth << 2 | way;
          } else {
            // Reached the other way first, at depth (entry >> 2) <= depth.
            entry |= way;
            reverses = depth + (entry >> 2) <= static_cast<std::uint32_t>(max_steps);
            if (reverses)
              break;
          }
          next_.push_back({u, u_reversed});
        }
        if (reverses)
          break;
      }
      frontier_.swap(next_);
    }
    for (std::uint32_t t : touched_)
      reached_[t] = 0;
    return reverses;
  }

private:
  static constexpr std::uint32_t as_it_is = 1, the_other_way = 2;
  /// Per triangle: 0, or the depth it was first reached at (shifted by 2)
  /// and the ways it was reached.
  std::vector<std::uint32_t> reached_;
  std::vector<std::pair<std::uint32_t, bool>> frontier_, next_;
  std::vector<std::uint32_t> touched_;
};

} // namespace

std::vector<std::uint32_t> orientAlongNeighbours(std::vector<Triangle> &triangles,
                                                 const std::vector<std::uint32_t> &neighbours,
                                                 const std::vector<Eigen::Vector3d> &points,
                                                 std::vector<std::uint32_t> &triangle_component,
                                                 std::vector<bool> &component_orientable,
                                                 const Eigen::Vector3d *viewpoint) {
  // A consistent orientation, where one exists, is the same whatever order
  // it spreads in: each component's first triangle keeps its orientation
  // and the others follow across the manifold edges, joined in a parity
  // forest (whose roots are the first triangles) in any order. A component
  // where some join conflicts has none.
  const std::size_t count = triangles.size();
  ParityForest forest(count);
  std::vector<std::uint8_t> conflicted(count, 0);
  // Flipping exactly one of the two changes whether they agree.
  auto join = [&](std::uint32_t t, std::uint32_t u) {
    return forest.join(t, u, !consistentlyOriented(triangles[t], triangles[u]));
  };
  const ParallelJoins edges(triangles, points.size(), neighbours);
  edges.forEachEdge([&](std::uint32_t t, std::uint32_t u, std::size_t) {
    if (join(t, u) == ParityForest::Join::conflict)
      conflicted[t] = 1;
  });
  // Components numbered by their first triangles, in order; triangles of
  // orientable ones turned to agree with it.
  triangle_component.assign(count, 0);
  component_orientable.clear();
  std::vector<std::uint32_t> component_size;
  std::vector<std::uint8_t> flipped(count, 0);
  for (std::uint32_t t = 0; t < count; ++t) {
    const auto [root, flip] = forest.find(t);
    if (root == t) {
      triangle_component[t] = static_cast<std::uint32_t>(component_orientable.size());
      component_orientable.push_back(true);
      component_size.push_back(0);
    } else {
      triangle_component[t] = triangle_component[root];
    }
    flipped[t] = flip;
    ++component_size[triangle_component[t]];
  }
  forest = ParityForest(0);
  for (std::uint32_t t = 0; t < count; ++t)
    if (conflicted[t])
      component_orientable[triangle_component[t]] = false;
  std::vector<std::uint8_t>().swap(conflicted);
  forEachIndex(count, [&](std::size_t t) {
    if (flipped[t] && component_orientable[triangle_component[t]])
      std::swap(triangles[t][1], triangles[t][2]);
  });
  std::vector<std::uint8_t>().swap(flipped);
  // Each manifold edge once: from its lower-numbered triangle.
  auto forEachEdgeOf = [&](std::uint32_t t, const auto &visit) {
    for (std::uint32_t u : neighboursOf(neighbours, t))
      if (u > t)
        visit(u);
  };

  // Where none exists, orientation follows a maximum spanning forest on
  // flatness (edges joined flattest first, Kruskal's order), so that the
  // edges left inconsistent are the component's most bent ones, i.e. where
  // the twist is. Each component's first triangle keeps its orientation.
  auto inTwistedComponent = [&](std::uint32_t t) {
    return !component_orientable[triangle_component[t]];
  };
  const bool any_twisted = std::find(component_orientable.begin(), component_orientable.end(),
                                     false) != component_orientable.end();
  std::vector<std::uint32_t> to_cut;
  if (any_twisted) {
    // Kruskal's forest after the flat edges does not depend on their order
    // when no cycle of flat edges is twisted: the same triangles end up
    // together with the same relative flips. So they are joined unsorted, in
    // parallel (ParallelJoins), and only the few bent edges are kept and
    // sorted; the bending is computed as the edges come, never stored for
    // every edge (at 10M points that was 240 MB). A twist among flat edges
    // needs Kruskal's order throughout. Ties are broken by the edge's key.
    forest = ParityForest(count);
    struct BentEdge {
      double bending;
      EdgeKey key;
      std::uint32_t t, u;
    };
    std::vector<BentEdge> bent_edges;
    auto bentEdge = [&](std::uint32_t t, std::uint32_t u, double bending) {
      return BentEdge{bending, sharedEdge(triangles[t], triangles[u]), t, u};
    };
    // The flat edges joined in parallel, the bent ones kept per part.
    std::vector<std::vector<BentEdge>> bent_in_part(edges.parts());
    std::vector<std::uint8_t> flat_twist_in_part(bent_in_part.size(), 0);
    edges.forEachEdge([&](std::uint32_t t, std::uint32_t u, std::size_t part) {
      if (!inTwistedComponent(t))
        return;
      const double bending = kruskalBendingAt(t, u, triangles, points);
      if (bending >= kruskal_flat_bending)
        bent_in_part[part].push_back(bentEdge(t, u, bending));
      else if (join(t, u) == ParityForest::Join::conflict)
        flat_twist_in_part[part] = 1;
    });
    if (std::find(flat_twist_in_part.begin(), flat_twist_in_part.end(), 1) !=
        flat_twist_in_part.end()) {
      // A twist among flat edges: Kruskal's order throughout.
      forest = ParityForest(count);
      for (std::vector<BentEdge> &part : bent_in_part)
        part.clear();
      edges.forEachEdge([&](std::uint32_t t, std::uint32_t u, std::size_t part) {
        if (inTwistedComponent(t))
          bent_in_part[part].push_back(bentEdge(t, u, bendingAt(t, u, triangles, points)));
      });
    }
    for (std::vector<BentEdge> &part : bent_in_part) {
      bent_edges.insert(bent_edges.end(), part.begin(), part.end());
      std::vector<BentEdge>().swap(part);
    }
    std::sort(bent_edges.begin(), bent_edges.end(), [](const BentEdge &a, const BentEdge &b) {
      return a.bending < b.bending || (a.bending == b.bending && a.key < b.key);
    });
    // An edge that closes a cycle leaves the forest as it is, consistent or not.
    for (const BentEdge &bent : bent_edges)
      join(bent.t, bent.u);
    std::vector<BentEdge>().swap(bent_edges);
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      if (inTwistedComponent(t) && forest.find(t).second)
        std::swap(triangles[t][1], triangles[t][2]);
    forest = ParityForest(0);

    // The edges still inconsistent, in key order.
    struct Conflict {
      EdgeKey key;
      std::uint32_t t, u;
      bool operator<(const Conflict &other) const { return key < other.key; }
    };
    std::vector<Conflict> conflicts;
    {
      // Found in parallel (bit k: t's k-th edge to a later triangle), listed in order.
      std::vector<std::uint8_t> inconsistent(triangles.size(), 0);
      forEachIndex(triangles.size(), [&](std::size_t i) {
        const std::uint32_t t = static_cast<std::uint32_t>(i);
        if (!inTwistedComponent(t))
          return;
        std::uint8_t edge = 1;
        forEachEdgeOf(t, [&](std::uint32_t u) {
          if (!consistentlyOriented(triangles[t], triangles[u]))
            inconsistent[t] |= edge;
          edge = static_cast<std::uint8_t>(edge << 1);
        });
      });
      for (std::uint32_t t = 0; t < triangles.size(); ++t) {
        if (!inconsistent[t])
          continue;
        std::uint8_t edge = 1;
        forEachEdgeOf(t, [&](std::uint32_t u) {
          if (inconsistent[t] & edge)
            conflicts.push_back({sharedEdge(triangles[t], triangles[u]), t, u});
          edge = static_cast<std::uint8_t>(edge << 1);
        });
      }
    }
    std::sort(conflicts.begin(), conflicts.end());
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
    auto moreEdgeOn = [&](std::uint32_t t, std::uint32_t u) {
      auto facing = [&](std::uint32_t triangle) {
        return facingOf(points[triangles[triangle][0]], points[triangles[triangle][1]],
                        points[triangles[triangle][2]], *viewpoint);
      };
      return facing(t) < facing(u) ? t : u;
    };
    TwistWalk walk(triangles.size());
    std::vector<bool> holds_real_twist(component_size.size(), false);
    for (const Conflict &conflict : conflicts) {
      const std::uint32_t t = conflict.t, u = conflict.u;
      const std::uint32_t component = triangle_component[t];
      const int long_walk = longTwistSteps(component_size[component]);
      auto localTwist = [&]() {
        if (walk.reversesWithin(t, max_local_twist_steps, triangles, neighbours))
          return true;
        if (holds_real_twist[component] || long_walk <= max_local_twist_steps)
          return false;
        if (walk.reversesWithin(t, long_walk, triangles, neighbours))
          return true;
        holds_real_twist[component] = true;
        return false;
      };
      if (viewpoint)
        to_cut.push_back(moreEdgeOn(t, u));
      else if (bendingAt(t, u, triangles, points) > max_untwist_bending || localTwist()) {
        to_cut.push_back(t);
        to_cut.push_back(u);
      }
    }
  }
  // Outward for closed surfaces; towards the viewpoint for open ones when
  // there is one (area-weighted); a fixed, reproducible choice otherwise.
  // The signs are the exact sums', so any order of the triangles, or of
  // parts of them, gives them.
  const std::size_t components = component_size.size();
  ExactSigns signed_volume(components), facing(viewpoint ? components : 0);
  std::vector<bool> closed(components, true);
  auto forEachSideTerm = [&](const auto &add) {
    for (std::uint32_t t = 0; t < count; ++t) {
      const std::uint32_t component = triangle_component[t];
      if (!component_orientable[component])
        continue;
      const Eigen::Vector3d &a = points[triangles[t][0]], &b = points[triangles[t][1]],
                            &c = points[triangles[t][2]];
      add(t, component, a.dot(b.cross(c)),
          viewpoint ? (b - a).cross(c - a).dot(*viewpoint - a) : 0.0);
    }
  };
  forEachSideTerm([&](std::uint32_t t, std::uint32_t component, double volume, double towards) {
    signed_volume.add(component, volume);
    if (viewpoint)
      facing.add(component, towards);
    if (neighboursOf(neighbours, t).size() != 3)
      closed[component] = false;
  });
  const bool exact_volume = signed_volume.needsExactPass();
  const bool exact_facing = viewpoint && facing.needsExactPass();
  if (exact_volume || exact_facing)
    forEachSideTerm([&](std::uint32_t, std::uint32_t component, double volume, double towards) {
      signed_volume.addExactly(component, volume);
      if (exact_facing)
        facing.addExactly(component, towards);
    });
  std::vector<std::uint8_t> turn(components, 0);
  for (std::size_t component = 0; component < components; ++component)
    turn[component] = component_orientable[component] &&
                      (viewpoint && !closed[component] ? facing.sign(component)
                                                       : signed_volume.sign(component)) < 0;
  forEachIndex(count, [&](std::size_t t) {
    if (turn[triangle_component[t]])
      std::swap(triangles[t][1], triangles[t][2]);
  });
  return to_cut;
}

} // namespace detail

std::vector<std::uint32_t> orientComponents(std::vector<Triangle> &triangles,
                                            const std::vector<Eigen::Vector3d> &points,
                                            std::vector<std::uint32_t> &triangle_component,
                                            std::vector<bool> &component_orientable,
                                            const Eigen::Vector3d *viewpoint) {
  return detail::orientAlongNeighbours(triangles, detail::meshEdges(triangles, true).neighbours,
                                       points, triangle_component, component_orientable, viewpoint);
}

} // namespace pcl_ms
