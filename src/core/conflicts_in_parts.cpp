// SPDX-License-Identifier: GPL-3.0-or-later
// The twist repair's choice of triangles to cut over a triangle list held in
// parts (conflicts_in_parts.h; docs/algorithm.md, "Finishing in parts").
#include "conflicts_in_parts.h"

#include "finish_steps.h"
#include "numbering.h"
#include "process_bytes.h"
#include "twist_bending.h"

#include <pcl_ms/costs.h>

#include <algorithm>
#include <unordered_map>

namespace pcl_ms {
namespace detail {
namespace {

/// A request for triangle `u`'s corners and their points.
struct TriangleRequest {
  std::uint64_t u;
  std::uint32_t asker;
};

struct TriangleAnswer {
  std::uint64_t u;
  Triangle corners;
  double points[9];
};

/// A conflict that only a walk decides, on process 0.
struct Pending {
  EdgeKey key;
  std::uint64_t t, u, component;
  bool operator<(const Pending &other) const { return key < other.key; }
};

/// An orientation-reversing walk to try: from `start`, at most max_steps.
struct WalkStart {
  std::uint64_t start;
  std::int32_t max_steps;
};

/// One step of a walk, to the holder of triangle `to`: the corners of the
/// triangle it comes from (as turned), whether the walk reached that one
/// reversed, and the depth it reaches `to` at.
struct WalkStep {
  std::uint64_t to;
  Triangle from_corners;
  std::uint32_t walk;
  std::uint32_t depth;
  std::uint8_t reversed;
};

/// Whether each walk returns to its start reversed within its steps, on
/// every process: one process's breadth-first search (TwistWalk in
/// orientation.cpp), a depth a round for all walks at once, each state on
/// the holder of its triangle. A walk of length L passes a state at depth
/// ceil(L / 2) whose mirror image is at depth L - ceil(L / 2), so the
/// search stops at half the steps, at a triangle reached both ways at
/// depths adding up to max_steps or less. Which states each depth reaches
/// does not depend on the order of the steps, so neither does the answer.
std::vector<std::uint8_t> reversingWalks(const std::vector<WalkStart> &walks,
                                         const std::vector<Triangle> &turned, std::uint64_t first,
                                         const std::vector<std::uint64_t> &firsts,
                                         const MeshEdgesPart &edges, ProcessGroup &group) {
  constexpr std::uint32_t as_it_is = 1, the_other_way = 2;
  const auto processes = static_cast<std::size_t>(group.processes());
  const auto mineAt = [&](std::uint64_t t) { return t >= first && t - first < turned.size(); };
  // Per (walk, triangle of the run): the depth it was first reached at
  // (shifted by 2) and the ways it was reached.
  std::unordered_map<std::uint64_t, std::uint32_t> reached;
  const auto stateKey = [](std::uint32_t walk, std::uint64_t local) {
    return std::uint64_t{walk} << 32 | local;
  };
  struct State {
    std::uint32_t walk;
    std::uint32_t local;
    std::uint8_t reversed;
  };
  std::vector<State> frontier;
  std::vector<std::uint8_t> found(walks.size(), 0);
  int rounds = 0;
  for (std::uint32_t w = 0; w < walks.size(); ++w) {
    rounds = std::max(rounds, (walks[w].max_steps + 1) / 2);
    if (mineAt(walks[w].start)) {
      const auto local = static_cast<std::uint32_t>(walks[w].start - first);
      reached[stateKey(w, local)] = as_it_is; // at depth 0
      frontier.push_back({w, local, 0});
    }
  }
  for (int step = 0; step < rounds; ++step) {
    const auto depth = static_cast<std::uint32_t>(step) + 1;
    std::vector<std::vector<WalkStep>> steps_out(processes);
    for (const State &state : frontier) {
      if (found[state.walk] || step >= (walks[state.walk].max_steps + 1) / 2)
        continue;
      for (std::size_t k = 0; k < 3; ++k) {
        const std::uint64_t u = edges.neighbours[3 * std::size_t{state.local} + k];
        if (u == no_neighbour_in_parts)
          break;
        steps_out[runHolding(firsts, u)].push_back(
            {u, turned[state.local], state.walk, depth, state.reversed});
      }
    }
    std::vector<State> next;
    deliver(steps_out, group, [&](const WalkStep &taken) {
      if (found[taken.walk])
        return;
      const auto local = static_cast<std::uint32_t>(taken.to - first);
      const bool reversed =
          (taken.reversed != 0) == consistentlyOriented(taken.from_corners, turned[local]);
      const std::uint32_t way = reversed ? the_other_way : as_it_is;
      std::uint32_t &entry = reached[stateKey(taken.walk, local)];
      if (entry & way)
        return;
      if (entry == 0) {
        entry = taken.depth << 2 | way;
      } else {
        // Reached the other way first, at depth (entry >> 2) <= depth.
        entry |= way;
        if (taken.depth + (entry >> 2) <= static_cast<std::uint32_t>(walks[taken.walk].max_steps))
          found[taken.walk] = 1;
      }
      next.push_back({taken.walk, local, static_cast<std::uint8_t>(reversed)});
    });
    // Every process learns which walks ended, and whether any goes on.
    std::vector<std::uint64_t> ended(found.begin(), found.end());
    ended.push_back(next.size());
    group.sum(ended);
    for (std::size_t w = 0; w < found.size(); ++w)
      found[w] = ended[w] > 0;
    if (ended.back() == 0)
      break;
    frontier.swap(next);
  }
  return found;
}

} // namespace

std::vector<std::uint64_t>
conflictCutsInParts(const std::vector<Triangle> &turned, std::uint64_t first,
                    const MeshEdgesPart &edges, const ComponentsPart &components,
                    const CornerPoints &corners, const std::vector<TwistConflict> &conflicts,
                    const Eigen::Vector3d *viewpoint, ProcessGroup &group) {
  const auto processes = static_cast<std::size_t>(group.processes());
  const bool on_zero = group.process() == 0;
  const std::vector<std::uint64_t> firsts =
      runFirsts(turned.size(), first, group, "conflictCutsInParts");
  // The triangle across each conflict, with its points, from its holder.
  std::vector<TriangleAnswer> across;
  {
    std::vector<std::vector<TriangleRequest>> requests_out(processes);
    for (const TwistConflict &conflict : conflicts)
      requests_out[runHolding(firsts, conflict.u)].push_back(
          {conflict.u, static_cast<std::uint32_t>(group.process())});
    std::vector<std::vector<TriangleAnswer>> answers_out(processes);
    deliver(requests_out, group, [&](const TriangleRequest &request) {
      TriangleAnswer answer{request.u, turned[static_cast<std::size_t>(request.u - first)], {}};
      for (int k = 0; k < 3; ++k)
        for (int axis = 0; axis < 3; ++axis)
          answer.points[3 * k + axis] = corners.of(answer.corners[k])[axis];
      answers_out[request.asker].push_back(answer);
    });
    deliver(answers_out, group, [&](const TriangleAnswer &answer) { across.push_back(answer); });
    std::sort(across.begin(), across.end(),
              [](const TriangleAnswer &a, const TriangleAnswer &b) { return a.u < b.u; });
  }

  // Decided here: with a viewpoint, and folds; the rest wait for walks.
  std::vector<std::uint64_t> cuts;
  std::vector<Pending> pending;
  for (const TwistConflict &conflict : conflicts) {
    const Triangle &t_corners = turned[static_cast<std::size_t>(conflict.t - first)];
    const TriangleAnswer &u_side = *std::lower_bound(
        across.begin(), across.end(), conflict.u,
        [](const TriangleAnswer &answer, std::uint64_t u) { return answer.u < u; });
    const auto uPoint = [&](int k) -> Eigen::Vector3d {
      return {u_side.points[3 * k], u_side.points[3 * k + 1], u_side.points[3 * k + 2]};
    };
    if (viewpoint) {
      const double t_facing = facingOf(corners.of(t_corners[0]), corners.of(t_corners[1]),
                                       corners.of(t_corners[2]), *viewpoint);
      const double u_facing = facingOf(uPoint(0), uPoint(1), uPoint(2), *viewpoint);
      cuts.push_back(t_facing < u_facing ? conflict.t : conflict.u);
      continue;
    }
    const EdgeKey edge = sharedEdge(t_corners, u_side.corners);
    if (bendingAngle(corners.of(lowVertex(edge)), corners.of(highVertex(edge)),
                     corners.of(t_corners[apexCorner(t_corners, edge)]),
                     uPoint(apexCorner(u_side.corners, edge))) > max_untwist_bending) {
      cuts.push_back(conflict.t);
      cuts.push_back(conflict.u);
      continue;
    }
    pending.push_back({conflict.key, conflict.t, conflict.u,
                       components.component[static_cast<std::size_t>(conflict.t - first)]});
  }
  if (totalOver(pending.size(), group) == 0)
    return cuts;

  // Process 0: the waiting conflicts in key order; every process: the sizes
  // of their components.
  std::vector<Pending> waiting;
  gatherAtZero<Pending>(
      pending.size(), [&](std::size_t i) { return pending[i]; },
      [&](std::size_t, const Pending &one) { waiting.push_back(one); }, group);
  std::sort(waiting.begin(), waiting.end());
  std::vector<std::uint64_t> waiting_components;
  for (const Pending &one : waiting)
    waiting_components.push_back(one.component);
  fromZeroToAll(waiting_components, group);
  const Numbering<std::uint64_t> twisted(std::move(waiting_components));
  std::vector<std::uint64_t> size(twisted.size(), 0);
  for (std::uint64_t component : components.component)
    if (twisted.contains(component))
      ++size[twisted(component)];
  group.sum(size);

  // Short walks for all at once.
  std::vector<WalkStart> walks;
  for (const Pending &one : waiting)
    walks.push_back({one.t, max_local_twist_steps});
  fromZeroToAll(walks, group);
  const std::vector<std::uint8_t> short_twist =
      reversingWalks(walks, turned, first, firsts, edges, group);

  // Long walks in waves: each wave the first undecided conflict of each
  // component that needs one, so that a component's long walks follow each
  // other in key order and one that fails (a real twist) stops the rest.
  enum : std::uint8_t { undecided, cut, kept };
  std::vector<std::uint8_t> verdict(waiting.size(), undecided);
  std::vector<std::uint8_t> real_twist(twisted.size(), 0);
  while (true) {
    std::vector<WalkStart> wave;
    std::vector<std::size_t> wave_conflict;
    if (on_zero) {
      std::vector<std::uint8_t> in_wave(twisted.size(), 0);
      for (std::size_t i = 0; i < waiting.size(); ++i) {
        if (verdict[i] != undecided)
          continue;
        const std::size_t component = twisted(waiting[i].component);
        const int long_walk = longTwistSteps(size[component]);
        if (short_twist[i])
          verdict[i] = cut;
        else if (real_twist[component] || long_walk <= max_local_twist_steps)
          verdict[i] = kept;
        else if (!in_wave[component]) {
          in_wave[component] = 1;
          wave.push_back({waiting[i].t, long_walk});
          wave_conflict.push_back(i);
        }
      }
    }
    fromZeroToAll(wave, group);
    if (wave.empty())
      break;
    const std::vector<std::uint8_t> long_twist =
        reversingWalks(wave, turned, first, firsts, edges, group);
    for (std::size_t k = 0; k < wave_conflict.size(); ++k) {
      const std::size_t i = wave_conflict[k];
      verdict[i] = long_twist[k] ? cut : kept;
      if (!long_twist[k])
        real_twist[twisted(waiting[i].component)] = 1;
    }
  }
  for (std::size_t i = 0; i < waiting.size(); ++i)
    if (verdict[i] == cut) {
      cuts.push_back(waiting[i].t);
      cuts.push_back(waiting[i].u);
    }
  return cuts;
}

} // namespace detail
} // namespace pcl_ms
