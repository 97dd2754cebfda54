// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4's edge scan over a triangle list held in parts, and its updates
// for fillings and cuts (edges_in_parts.h; docs/algorithm.md, "Finishing in
// parts").
#include "edges_in_parts.h"

#include "finish_steps.h"
#include "process_bytes.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace pcl_ms {
namespace detail {
namespace {

/// An edge's key with a number, ordered by key then number. The scan sends
/// each edge to its judge with the number of its triangle times 4 plus the
/// edge's place k in it (corners k and k + 1), so that the answer needs no
/// key; elsewhere the number is a triangle's.
struct KeyedEdge {
  EdgeKey key;
  std::uint64_t number;
  bool operator<(const KeyedEdge &other) const {
    return key < other.key || (key == other.key && number < other.number);
  }
};

/// The judge's answer to the holder of a triangle's edge: the triangle
/// across it, or no_neighbour_in_parts for a boundary edge.
struct EdgeVerdict {
  std::uint64_t triangle_edge; // as in KeyedEdge::number
  std::uint64_t across;
};

/// The rounds a scan takes to send `values` from this process, `per_round`
/// at a time, on every process: the scan goes in rounds so that no process
/// holds all its messages at once (a rank's peak is then its share of the
/// surface, not three times that).
std::uint64_t roundsFor(std::size_t values, std::size_t per_round, ProcessGroup &group) {
  return maximumOver((values + per_round - 1) / per_round, group);
}

/// A triangle's edge keys in ascending order.
std::array<EdgeKey, 3> sortedKeys(const Triangle &t) {
  std::array<EdgeKey, 3> keys;
  for (int k = 0; k < 3; ++k)
    keys[static_cast<std::size_t>(k)] = edgeKey(t[k], t[(k + 1) % 3]);
  std::sort(keys.begin(), keys.end());
  return keys;
}

/// Whether `key` is on the boundary of `edges` with triangle `triangle`.
bool openAt(const MeshEdgesPart &edges, EdgeKey key, std::uint64_t triangle) {
  const auto at = std::lower_bound(edges.boundary.begin(), edges.boundary.end(), key);
  return at != edges.boundary.end() && *at == key &&
         edges.boundary_triangle[static_cast<std::size_t>(at - edges.boundary.begin())] == triangle;
}

/// Boundary edges that open: (key, triangle), sorted.
using OpenedEdges = std::vector<KeyedEdge>;

/// The boundary of `edges` without the entries `goes(e)` marks, with
/// `opened` (no key of which is on it), in key order; every triangle
/// number through `renumbered`.
template <typename Goes, typename Renumbered>
void updateBoundary(MeshEdgesPart &edges, const OpenedEdges &opened, const Goes &goes,
                    const Renumbered &renumbered) {
  std::vector<EdgeKey> boundary;
  std::vector<std::uint64_t> boundary_triangle;
  std::size_t o = 0;
  for (std::size_t e = 0; e <= edges.boundary.size(); ++e) {
    for (; o < opened.size() && (e == edges.boundary.size() || opened[o].key < edges.boundary[e]);
         ++o) {
      boundary.push_back(opened[o].key);
      boundary_triangle.push_back(renumbered(opened[o].number));
    }
    if (e < edges.boundary.size() && !goes(e)) {
      boundary.push_back(edges.boundary[e]);
      boundary_triangle.push_back(renumbered(edges.boundary_triangle[e]));
    }
  }
  edges.boundary = std::move(boundary);
  edges.boundary_triangle = std::move(boundary_triangle);
}

} // namespace

MeshEdgesPart meshEdgesInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                               std::uint64_t vertex_count, ProcessGroup &group,
                               std::size_t records_per_round) {
  if (totalOver(records_per_round < 3 ? 1 : 0, group) > 0)
    throw std::invalid_argument("meshEdgesInParts: fewer than 3 records a round");
  const auto processes = static_cast<std::size_t>(group.processes());
  const std::vector<std::uint64_t> firsts =
      runFirsts(mine.size(), first, group, "meshEdgesInParts (triangles)");
  std::uint64_t outside = 0;
  for (const Triangle &t : mine)
    for (VertexIndex v : t)
      outside += v >= vertex_count;
  if (totalOver(outside, group) > 0)
    throw std::invalid_argument("meshEdgesInParts: a triangle has a corner beyond the points");

  const auto judgeOf = [&](EdgeKey key) {
    return static_cast<std::size_t>(std::uint64_t{lowVertex(key)} * processes / vertex_count);
  };
  const auto keyOf = [&](std::size_t t, std::size_t k) {
    return edgeKey(mine[t][k], mine[t][(k + 1) % 3]);
  };

  // Each judge learns how many edges it gets, to hold them in one array.
  std::vector<std::vector<std::uint64_t>> counts(processes, std::vector<std::uint64_t>(1, 0));
  for (std::size_t t = 0; t < mine.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k)
      ++counts[judgeOf(keyOf(t, k))][0];
  std::uint64_t incoming = 0;
  deliver(counts, group, [&](std::uint64_t count) { incoming += count; });
  std::vector<KeyedEdge> uses;
  uses.reserve(static_cast<std::size_t>(incoming));
  const std::size_t triangles_per_round = records_per_round / 3;
  const std::uint64_t use_rounds = roundsFor(mine.size(), triangles_per_round, group);
  std::vector<std::vector<KeyedEdge>> uses_out(processes);
  for (std::uint64_t round = 0; round < use_rounds; ++round) {
    const std::size_t begin = std::min<std::size_t>(mine.size(), round * triangles_per_round);
    const std::size_t end = std::min<std::size_t>(mine.size(), begin + triangles_per_round);
    for (std::size_t t = begin; t < end; ++t)
      for (std::size_t k = 0; k < 3; ++k) {
        const EdgeKey key = keyOf(t, k);
        uses_out[judgeOf(key)].push_back({key, 4 * (first + t) + k});
      }
    deliver(uses_out, group, [&](const KeyedEdge &use) { uses.push_back(use); });
  }
  parallelSort(uses.begin(), uses.end(), std::less<KeyedEdge>());

  // Judged in key order, a round's worth of edges at a time (an edge's
  // triangles are judged in the round where the first of them falls).
  MeshEdgesPart part;
  part.neighbours.assign(3 * mine.size(), no_neighbour_in_parts);
  std::vector<KeyedEdge> boundary; // (key, triangle)
  const auto holderOf = [&](std::uint64_t triangle_edge) {
    return runHolding(firsts, triangle_edge / 4);
  };
  const auto take = [&](const EdgeVerdict &verdict) {
    const std::size_t t = static_cast<std::size_t>(verdict.triangle_edge / 4 - first);
    const EdgeKey key = keyOf(t, static_cast<std::size_t>(verdict.triangle_edge % 4));
    if (verdict.across == no_neighbour_in_parts) {
      boundary.push_back({key, first + t});
    } else {
      part.neighbours[3 * t + slotOf(mine[t], key)] = verdict.across;
    }
  };
  std::vector<std::vector<EdgeVerdict>> verdicts_out(processes);
  bool crowded = false;
  const std::uint64_t verdict_rounds = roundsFor(uses.size(), records_per_round, group);
  std::size_t i = 0;
  for (std::uint64_t round = 0; round < verdict_rounds; ++round) {
    const std::size_t end = std::min<std::size_t>(uses.size(), (round + 1) * records_per_round);
    while (i < end) {
      std::size_t j = i;
      while (j < uses.size() && uses[j].key == uses[i].key)
        ++j;
      if (j - i == 1) {
        verdicts_out[holderOf(uses[i].number)].push_back({uses[i].number, no_neighbour_in_parts});
      } else if (j - i == 2) {
        const std::uint64_t t = uses[i].number, u = uses[i + 1].number;
        verdicts_out[holderOf(t)].push_back({t, u / 4});
        verdicts_out[holderOf(u)].push_back({u, t / 4});
      } else {
        crowded = true;
      }
      i = j;
    }
    deliver(verdicts_out, group, take);
  }
  std::vector<KeyedEdge>().swap(uses);
  // The rounds mix the judges' answers; a boundary edge has one triangle,
  // so its key alone orders it.
  std::sort(boundary.begin(), boundary.end());
  part.boundary.reserve(boundary.size());
  part.boundary_triangle.reserve(boundary.size());
  for (const KeyedEdge &edge : boundary) {
    part.boundary.push_back(edge.key);
    part.boundary_triangle.push_back(edge.number);
  }
  packSlots(part.neighbours, no_neighbour_in_parts);
  part.crowded = totalOver(crowded ? 1 : 0, group) > 0;
  return part;
}

void addTrianglesToEdgesInParts(MeshEdgesPart &edges, const std::vector<Triangle> &mine,
                                std::uint64_t first, std::size_t first_new, ProcessGroup &group) {
  if (totalOver(edges.crowded || first_new > mine.size() ? 1 : 0, group) > 0)
    throw std::invalid_argument("addTrianglesToEdgesInParts: a crowded list or no such triangles");
  const auto isMine = [&](std::uint64_t triangle) {
    return triangle >= first && triangle < first + mine.size();
  };
  // Every process gets every new edge, and every boundary edge they use.
  std::vector<KeyedEdge> own_uses;
  for (std::size_t t = first_new; t < mine.size(); ++t)
    for (int k = 0; k < 3; ++k)
      own_uses.push_back({edgeKey(mine[t][k], mine[t][(k + 1) % 3]), first + t});
  std::vector<KeyedEdge> uses = valuesOf<KeyedEdge>(group.gatherAll(bytesOf(own_uses)));
  std::sort(uses.begin(), uses.end());
  std::vector<KeyedEdge> own_closed; // (boundary key, its triangle)
  for (std::size_t i = 0; i < uses.size(); ++i)
    if (i == 0 || uses[i].key != uses[i - 1].key) {
      const auto at = std::lower_bound(edges.boundary.begin(), edges.boundary.end(), uses[i].key);
      if (at != edges.boundary.end() && *at == uses[i].key)
        own_closed.push_back(
            {uses[i].key,
             edges.boundary_triangle[static_cast<std::size_t>(at - edges.boundary.begin())]});
    }
  std::vector<KeyedEdge> closed = valuesOf<KeyedEdge>(group.gatherAll(bytesOf(own_closed)));
  std::sort(closed.begin(), closed.end());

  // Each edge decided alike on every process; each keeps what is its own.
  edges.neighbours.resize(3 * mine.size(), no_neighbour_in_parts);
  std::vector<std::pair<std::uint64_t, KeyedEdge>> links; // (triangle, {key, across})
  OpenedEdges opened;
  const auto link = [&](std::uint64_t t, EdgeKey key, std::uint64_t u) {
    if (isMine(t))
      links.push_back({t, {key, u}});
  };
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key)
      ++j;
    const EdgeKey key = uses[i].key;
    const auto at = std::lower_bound(closed.begin(), closed.end(), KeyedEdge{key, 0});
    const bool was_boundary = at != closed.end() && at->key == key;
    const std::size_t count = j - i + (was_boundary ? 1 : 0);
    const std::uint64_t one = was_boundary ? at->number : uses[i].number;
    const std::uint64_t other = uses[j - 1].number;
    if (count == 2) {
      link(one, key, other);
      link(other, key, one);
    } else if (count == 1) {
      if (isMine(one))
        opened.push_back({key, one});
    } else {
      edges.crowded = true; // three or more: not manifold, no neighbours
    }
    i = j;
  }
  // A linked triangle's slots: its manifold edges' neighbours in key order.
  // Before, its manifold edges were those not on its boundary (the list was
  // not crowded), their neighbours in the same order.
  std::sort(links.begin(), links.end(), [](const auto &a, const auto &b) {
    return a.first < b.first || (a.first == b.first && a.second.key < b.second.key);
  });
  for (std::size_t i = 0; i < links.size();) {
    std::size_t j = i;
    while (j < links.size() && links[j].first == links[i].first)
      ++j;
    const std::size_t t = static_cast<std::size_t>(links[i].first - first);
    const std::array<EdgeKey, 3> keys = sortedKeys(mine[t]);
    std::uint64_t *slots = &edges.neighbours[3 * t];
    std::array<std::uint64_t, 3> by_key;
    std::size_t held = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      const auto gained = std::find_if(links.begin() + static_cast<std::ptrdiff_t>(i),
                                       links.begin() + static_cast<std::ptrdiff_t>(j),
                                       [&](const auto &l) { return l.second.key == keys[k]; });
      const bool was_open = openAt(edges, keys[k], first + t);
      if (gained != links.begin() + static_cast<std::ptrdiff_t>(j))
        by_key[k] = gained->second.number;
      else if (t < first_new && !was_open)
        by_key[k] = slots[held++];
      else
        by_key[k] = no_neighbour_in_parts;
    }
    std::copy(by_key.begin(), by_key.end(), slots);
    packSlotsOf(slots, no_neighbour_in_parts); // the others' slots are as they were
    i = j;
  }
  // The boundary without the closed edges, with the opened ones, in key order.
  std::sort(opened.begin(), opened.end());
  updateBoundary(
      edges, opened,
      [&](std::size_t e) {
        const auto at =
            std::lower_bound(closed.begin(), closed.end(), KeyedEdge{edges.boundary[e], 0});
        return at != closed.end() && at->key == edges.boundary[e];
      },
      [](std::uint64_t t) { return t; });
}

void dropFromEdgesInParts(MeshEdgesPart &edges, const std::vector<Triangle> &mine,
                          std::uint64_t first, const std::vector<std::size_t> &dropped,
                          ProcessGroup &group) {
  const auto processes = static_cast<std::size_t>(group.processes());
  const std::vector<std::uint64_t> firsts =
      runFirsts(mine.size(), first, group, "dropFromEdgesInParts (triangles)");
  const bool bad = !std::is_sorted(dropped.begin(), dropped.end()) ||
                   (!dropped.empty() && dropped.back() >= mine.size()) ||
                   edges.neighbours.size() != 3 * mine.size();
  if (totalOver(edges.crowded || bad ? 1 : 0, group) > 0)
    throw std::invalid_argument("dropFromEdgesInParts: a crowded list or no such triangles");
  std::vector<std::uint64_t> own_gone(dropped.size());
  for (std::size_t d = 0; d < dropped.size(); ++d)
    own_gone[d] = first + dropped[d];
  const std::vector<std::uint64_t> gone =
      valuesOf<std::uint64_t>(group.gatherAll(bytesOf(own_gone))); // ascending: runs in order
  const auto goes = [&](std::uint64_t t) {
    return std::binary_search(gone.begin(), gone.end(), t);
  };

  // A triangle that goes tells each neighbour that stays which edge opens:
  // its slots hold the neighbours across its edges off its boundary, in key
  // order (the list is not crowded).
  struct Opening {
    std::uint64_t stays;
    EdgeKey key;
    std::uint64_t went;
  };
  std::vector<std::vector<Opening>> openings(processes);
  for (std::size_t t : dropped) {
    const std::uint64_t *slots = &edges.neighbours[3 * t];
    std::size_t held = 0;
    for (EdgeKey key : sortedKeys(mine[t])) {
      if (openAt(edges, key, first + t))
        continue;
      const std::uint64_t u = slots[held++];
      if (!goes(u))
        openings[runHolding(firsts, u)].push_back({u, key, first + t});
    }
  }
  OpenedEdges opened;
  deliver(openings, group, [&](const Opening &opening) {
    std::uint64_t *slots = &edges.neighbours[3 * static_cast<std::size_t>(opening.stays - first)];
    std::fill(std::remove(slots, slots + 3, opening.went), slots + 3, no_neighbour_in_parts);
    opened.push_back({opening.key, opening.stays});
  });

  // The numbers of the list left: each moves down by those gone before it.
  const auto renumbered = [&](std::uint64_t t) {
    return t -
           static_cast<std::uint64_t>(std::lower_bound(gone.begin(), gone.end(), t) - gone.begin());
  };
  std::size_t write = 0;
  for (std::size_t t = 0, d = 0; t < mine.size(); ++t) {
    if (d < dropped.size() && dropped[d] == t) {
      ++d;
      continue;
    }
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint64_t u = edges.neighbours[3 * t + k];
      edges.neighbours[write++] = u == no_neighbour_in_parts ? u : renumbered(u);
    }
  }
  edges.neighbours.resize(write);
  // The boundary without the edges of triangles gone, with the opened ones,
  // in key order (an opened edge had two triangles: it was not on it).
  std::sort(opened.begin(), opened.end());
  updateBoundary(
      edges, opened, [&](std::size_t e) { return goes(edges.boundary_triangle[e]); }, renumbered);
}

} // namespace detail
} // namespace pcl_ms
