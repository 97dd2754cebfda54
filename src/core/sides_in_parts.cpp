// SPDX-License-Identifier: GPL-3.0-or-later
// Each orientable component's side over a triangle list held in parts
// (sides_in_parts.h; docs/algorithm.md, "Finishing in parts").
#include "sides_in_parts.h"

#include "exact_signs.h"
#include "process_bytes.h"
#include "sort_unique.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <utility>

namespace pcl_ms {
namespace detail {
namespace {

/// A process's sums for one component, to the component's holder.
struct SidePartial {
  std::uint64_t component;
  ExactSigns::Partial volume;
  ExactSigns::Partial facing;
  std::uint32_t process;
  std::uint8_t open; // a triangle of it has an edge without a manifold neighbour
};

/// The holder's answer for a component.
enum Verdict : std::uint8_t { keep, turn, send_volume_terms, send_facing_terms };

struct SideVerdict {
  std::uint64_t component;
  std::uint8_t verdict;
};

/// A term of a sum too close to zero, to the component's holder.
struct SideTerm {
  std::uint64_t component;
  double term;
};

std::size_t indexIn(const std::vector<std::uint64_t> &sorted, std::uint64_t value) {
  return static_cast<std::size_t>(std::lower_bound(sorted.begin(), sorted.end(), value) -
                                  sorted.begin());
}

} // namespace

std::vector<std::uint8_t> sideTurnsInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                                           const MeshEdgesPart &edges,
                                           const ComponentsPart &components,
                                           const CornerPoints &corners,
                                           const Eigen::Vector3d *viewpoint, ProcessGroup &group) {
  const auto processes = static_cast<std::size_t>(group.processes());
  const std::size_t count = mine.size();
  const std::vector<std::uint64_t> firsts =
      runFirsts(count, first, group, "sideTurnsInParts (triangles)");
  const auto holderOf = [&](std::uint64_t triangle) { return runHolding(firsts, triangle); };

  // The run's orientable components, ascending.
  std::vector<std::uint64_t> held;
  for (std::size_t t = 0; t < count; ++t)
    if (components.orientable[t])
      held.push_back(components.component[t]);
  detail::sortUnique(held);

  // The terms of one process's sums (orientation.cpp), from the triangles
  // turned to agree with their components' first triangles.
  const auto forEachTerm = [&](const auto &add) {
    for (std::size_t t = 0; t < count; ++t) {
      if (!components.orientable[t])
        continue;
      Triangle agreeing = mine[t];
      if (components.flipped[t])
        std::swap(agreeing[1], agreeing[2]);
      const Eigen::Vector3d &a = corners.of(agreeing[0]), &b = corners.of(agreeing[1]),
                            &c = corners.of(agreeing[2]);
      add(t, indexIn(held, components.component[t]), a.dot(b.cross(c)),
          viewpoint ? (b - a).cross(c - a).dot(*viewpoint - a) : 0.0);
    }
  };
  std::vector<SidePartial> partials;
  {
    ExactSigns volume(held.size()), facing(held.size());
    std::vector<std::uint8_t> open(held.size(), 0);
    forEachTerm([&](std::size_t t, std::size_t k, double volume_term, double facing_term) {
      volume.add(k, volume_term);
      facing.add(k, facing_term);
      if (edges.neighbours[3 * t + 2] == no_neighbour_in_parts) // slots are packed
        open[k] = 1;
    });
    std::vector<std::vector<SidePartial>> partials_out(processes);
    for (std::size_t k = 0; k < held.size(); ++k)
      partials_out[holderOf(held[k])].push_back({held[k], volume.partial(k), facing.partial(k),
                                                 static_cast<std::uint32_t>(group.process()),
                                                 open[k]});
    deliver(partials_out, group, [&](const SidePartial &partial) { partials.push_back(partial); });
  }

  // The holder's part: the components whose first triangle is here, their
  // sums merged (signs by the exact sums: any grouping decides alike).
  std::vector<std::uint64_t> owned;
  for (const SidePartial &partial : partials)
    owned.push_back(partial.component);
  detail::sortUnique(owned);
  ExactSigns owned_volume(owned.size()), owned_facing(owned.size());
  std::vector<std::uint8_t> owned_open(owned.size(), 0);
  for (const SidePartial &partial : partials) {
    const std::size_t k = indexIn(owned, partial.component);
    owned_volume.merge(k, partial.volume);
    owned_facing.merge(k, partial.facing);
    owned_open[k] |= partial.open;
  }
  owned_volume.needsExactPass();
  owned_facing.needsExactPass();
  // Closed surfaces turn outward, open ones towards the viewpoint.
  const auto usesFacing = [&](std::size_t k) { return viewpoint && owned_open[k]; };
  const auto sumsOf = [&](std::size_t k) -> ExactSigns & {
    return usesFacing(k) ? owned_facing : owned_volume;
  };
  const auto verdictOf = [&](std::size_t k, bool exact_pass_made) {
    if (sumsOf(k).needsExactly(k) && !exact_pass_made)
      return usesFacing(k) ? send_facing_terms : send_volume_terms;
    return sumsOf(k).sign(k) < 0 ? turn : keep;
  };
  std::vector<std::uint8_t> verdict(held.size(), keep);
  // To every process that sent sums: all verdicts, or after the exact pass
  // those it made.
  const auto answer = [&](bool exact_pass_made) {
    std::vector<std::vector<SideVerdict>> verdicts_out(processes);
    for (const SidePartial &partial : partials) {
      const std::size_t k = indexIn(owned, partial.component);
      if (!exact_pass_made || sumsOf(k).needsExactly(k))
        verdicts_out[partial.process].push_back({partial.component, verdictOf(k, exact_pass_made)});
    }
    deliver(verdicts_out, group, [&](const SideVerdict &answered) {
      verdict[indexIn(held, answered.component)] = answered.verdict;
    });
  };
  answer(false);

  // Sums too close to zero for their rounding bound: their terms, added
  // exactly on the holder.
  std::uint64_t waiting = 0;
  for (std::uint8_t v : verdict)
    waiting += v == send_volume_terms || v == send_facing_terms;
  if (totalOver(waiting, group) > 0) {
    std::vector<std::vector<SideTerm>> terms_out(processes);
    forEachTerm([&](std::size_t, std::size_t k, double volume_term, double facing_term) {
      if (verdict[k] == send_volume_terms || verdict[k] == send_facing_terms)
        terms_out[holderOf(held[k])].push_back(
            {held[k], verdict[k] == send_volume_terms ? volume_term : facing_term});
    });
    deliver(terms_out, group, [&](const SideTerm &term) {
      const std::size_t k = indexIn(owned, term.component);
      sumsOf(k).addExactly(k, term.term);
    });
    answer(true);
  }

  std::vector<std::uint8_t> turned(count, 0);
  for (std::size_t t = 0; t < count; ++t)
    if (components.orientable[t])
      turned[t] =
          components.flipped[t] ^
          static_cast<std::uint8_t>(verdict[indexIn(held, components.component[t])] == turn);
  return turned;
}

} // namespace detail
} // namespace pcl_ms
