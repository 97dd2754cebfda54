// SPDX-License-Identifier: GPL-3.0-or-later
// The twist repair's spanning forest over a triangle list held in parts
// (twists_in_parts.h; docs/algorithm.md, "Finishing in parts").
#include "twists_in_parts.h"

#include "finish_steps.h"
#include "pieces_in_parts.h"
#include "process_bytes.h"
#include "sort_unique.h"
#include "twist_bending.h"

#include <pcl_ms/costs.h>
#include <pcl_ms/disjoint_sets.h>

#include <algorithm>
#include <utility>

namespace pcl_ms {
namespace detail {
namespace {

/// An edge for process 0 to join the pieces of its triangles t < u along:
/// whether the pieces' turns must differ for t and u to agree.
struct PieceEdge {
  double bending;
  EdgeKey key;
  std::uint64_t t, u;
  std::uint64_t piece_t, piece_u;
  std::uint8_t pieces_differ;
  std::uint8_t flat;
};

/// One side of an edge between runs, to process 0: its triangle with its
/// corners' points, the triangle across, its piece and turn in that piece.
struct TwistSide {
  std::uint64_t triangle, across, piece;
  double points[9];
  Triangle corners;
  std::uint32_t process;
  std::uint8_t flip;
};

/// Process 0's answer: a piece's turn relative to its component's first
/// triangle.
struct PieceTurn {
  std::uint64_t piece;
  std::uint8_t flip;
};

/// The bending that orders edge pq (p the lower vertex) between apexes t
/// (of the lower-numbered triangle) and s: with flat edges joined first,
/// kruskalBending(); otherwise every edge's own.
double orderingBending(const Eigen::Vector3d &p, const Eigen::Vector3d &q, const Eigen::Vector3d &t,
                       const Eigen::Vector3d &s, bool everything_sorted) {
  return everything_sorted ? bendingAngle(p, q, t, s) : kruskalBending(p, q, t, s);
}

int cornerOf(const Triangle &corners, VertexIndex v) {
  return corners[0] == v ? 0 : corners[1] == v ? 1 : 2;
}

Eigen::Vector3d pointOf(const TwistSide &side, int k) {
  return {side.points[3 * k], side.points[3 * k + 1], side.points[3 * k + 2]};
}

/// Process 0's edges from the sides of the edges between runs: one per
/// manifold edge, as one process visits them (from the lower triangle, per
/// shared edge). Also notes which process holds each side's piece.
std::vector<PieceEdge> edgesOfSides(std::vector<TwistSide> &sides, bool everything_sorted,
                                    std::vector<std::pair<std::uint64_t, std::uint32_t>> &holders,
                                    std::vector<std::uint32_t> &lower_holder) {
  std::vector<PieceEdge> joined;
  forEachTrianglePair(sides, [&](std::size_t begin, std::size_t end) {
    const TwistSide &low = sides[begin], &high = sides[end - 1];
    holders.emplace_back(low.piece, low.process);
    holders.emplace_back(high.piece, high.process);
    const EdgeKey key = sharedEdge(low.corners, high.corners);
    const Eigen::Vector3d p = pointOf(low, cornerOf(low.corners, lowVertex(key))),
                          q = pointOf(low, cornerOf(low.corners, highVertex(key)));
    const double bending =
        orderingBending(p, q, pointOf(low, apexCorner(low.corners, key)),
                        pointOf(high, apexCorner(high.corners, key)), everything_sorted);
    const auto differ = static_cast<std::uint8_t>(!consistentlyOriented(low.corners, high.corners) ^
                                                  low.flip ^ high.flip);
    // One edge per shared edge, as the lower triangle's slots list them.
    for (std::size_t k = begin; k < end && sides[k].triangle == low.triangle; ++k) {
      joined.push_back(
          {bending, key, low.triangle, high.triangle, low.piece, high.piece, differ,
           static_cast<std::uint8_t>(!everything_sorted && bending < kruskal_flat_bending)});
      lower_holder.push_back(low.process);
    }
  });
  return joined;
}

} // namespace

TwistsPart twistForestInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                              const MeshEdgesPart &edges, const ComponentsPart &components,
                              const CornerPoints &corners, ProcessGroup &group) {
  const auto processes = static_cast<std::size_t>(group.processes());
  const auto me = static_cast<std::uint32_t>(group.process());
  const std::size_t count = mine.size();
  const auto mineAt = [&](std::uint64_t triangle) {
    return triangle >= first && triangle - first < count;
  };
  const auto twisted = [&](std::size_t t) { return !components.orientable[t]; };
  // Calls visit(t, u, slot) for each manifold edge of a twisted triangle t
  // of the run, within the run from the lower triangle only.
  const auto forEachEdge = [&](const auto &visit) {
    for (std::size_t t = 0; t < count; ++t)
      if (twisted(t))
        for (std::size_t k = 0; k < 3; ++k) {
          const std::uint64_t u = edges.neighbours[3 * t + k];
          if (u != no_neighbour_in_parts && (!mineAt(u) || u - first > t))
            visit(t, u);
        }
  };

  for (const bool everything_sorted : {false, true}) {
    // The run's pieces: its flat edges joined.
    ParityForest forest(count);
    bool flat_twist = false;
    struct OwnBent {
      double bending;
      std::size_t t, u;
    };
    std::vector<OwnBent> own_bent;
    forEachEdge([&](std::size_t t, std::uint64_t u_whole) {
      if (!mineAt(u_whole))
        return;
      const auto u = static_cast<std::size_t>(u_whole - first);
      const EdgeKey key = sharedEdge(mine[t], mine[u]);
      const double bending =
          orderingBending(corners.of(lowVertex(key)), corners.of(highVertex(key)),
                          corners.of(mine[t][apexCorner(mine[t], key)]),
                          corners.of(mine[u][apexCorner(mine[u], key)]), everything_sorted);
      if (!everything_sorted && bending < kruskal_flat_bending) {
        if (forest.join(static_cast<std::uint32_t>(t), static_cast<std::uint32_t>(u),
                        !consistentlyOriented(mine[t], mine[u])) == ParityForest::Join::conflict)
          flat_twist = true;
      } else {
        own_bent.push_back({bending, t, u});
      }
    });
    std::vector<std::uint64_t> piece(count);
    std::vector<std::uint8_t> flip(count);
    for (std::size_t t = 0; t < count; ++t) {
      const auto [root, turned] = forest.find(static_cast<std::uint32_t>(t));
      piece[t] = first + root;
      flip[t] = turned;
    }

    // To process 0: the run's bent edges between its pieces, and its sides
    // of the edges to other runs.
    std::vector<std::vector<PieceEdge>> bent_out(processes);
    for (const OwnBent &bent : own_bent)
      bent_out[0].push_back(
          {bent.bending, sharedEdge(mine[bent.t], mine[bent.u]), first + bent.t, first + bent.u,
           piece[bent.t], piece[bent.u],
           static_cast<std::uint8_t>(!consistentlyOriented(mine[bent.t], mine[bent.u]) ^
                                     flip[bent.t] ^ flip[bent.u]),
           0});
    std::vector<std::vector<TwistSide>> sides_out(processes);
    forEachEdge([&](std::size_t t, std::uint64_t u) {
      if (mineAt(u))
        return;
      TwistSide side{first + t, u, piece[t], {}, mine[t], me, flip[t]};
      for (int k = 0; k < 3; ++k)
        for (int axis = 0; axis < 3; ++axis)
          side.points[3 * k + axis] = corners.of(mine[t][k])[axis];
      sides_out[0].push_back(side);
    });
    std::vector<PieceEdge> piece_edges;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> holders;
    deliver(bent_out, group, [&](const PieceEdge &bent) { piece_edges.push_back(bent); });
    // Each local bent edge came from the process holding both its pieces.
    {
      std::vector<std::uint64_t> bent_counts = countsOf(own_bent.size(), group);
      std::size_t at = 0;
      for (std::uint32_t p = 0; p < bent_counts.size(); ++p)
        for (std::uint64_t i = 0; i < bent_counts[p] && me == 0; ++i, ++at) {
          holders.emplace_back(piece_edges[at].piece_t, p);
          holders.emplace_back(piece_edges[at].piece_u, p);
        }
    }
    std::vector<TwistSide> sides;
    deliver(sides_out, group, [&](const TwistSide &side) { sides.push_back(side); });
    const std::size_t own_edges = piece_edges.size();
    std::vector<std::uint32_t> cross_lower_holder;
    {
      std::vector<PieceEdge> cross =
          edgesOfSides(sides, everything_sorted, holders, cross_lower_holder);
      std::vector<TwistSide>().swap(sides);
      piece_edges.insert(piece_edges.end(), cross.begin(), cross.end());
    }

    // Process 0: the pieces numbered, the flat edges between them joined in
    // any order.
    std::vector<std::uint64_t> named;
    for (const PieceEdge &edge : piece_edges) {
      named.push_back(edge.piece_t);
      named.push_back(edge.piece_u);
    }
    const PieceNumbers numberOf(std::move(named));
    ParityForest piece_forest(numberOf.size());
    for (const PieceEdge &edge : piece_edges)
      if (edge.flat && piece_forest.join(numberOf(edge.piece_t), numberOf(edge.piece_u),
                                         edge.pieces_differ) == ParityForest::Join::conflict)
        flat_twist = true;
    if (totalOver(flat_twist ? 1 : 0, group) > 0 && !everything_sorted)
      continue; // a twisted cycle of flat edges: Kruskal's order throughout

    // Process 0: the bent edges flattest first (ties by key); an edge that
    // closes a cycle leaves the forest as it is.
    std::vector<std::size_t> order;
    for (std::size_t e = 0; e < piece_edges.size(); ++e)
      if (!piece_edges[e].flat)
        order.push_back(e);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      const PieceEdge &x = piece_edges[a], &y = piece_edges[b];
      return x.bending < y.bending || (x.bending == y.bending && x.key < y.key);
    });
    for (std::size_t e : order)
      piece_forest.join(numberOf(piece_edges[e].piece_t), numberOf(piece_edges[e].piece_u),
                        piece_edges[e].pieces_differ);
    std::vector<std::uint8_t> piece_flip(numberOf.size());
    for (std::uint32_t p = 0; p < numberOf.size(); ++p)
      piece_flip[p] = piece_forest.find(p).second;

    // Answers: each piece's turn to the processes holding it, and the edges
    // between runs left inconsistent to the holder of their lower triangle.
    detail::sortUnique(holders);
    std::vector<std::vector<PieceTurn>> turns_out(processes);
    for (const auto &[id, process] : holders)
      turns_out[process].push_back({id, piece_flip[numberOf(id)]});
    std::vector<std::vector<TwistConflict>> conflicts_out(processes);
    for (std::size_t e = own_edges; e < piece_edges.size(); ++e) {
      const PieceEdge &edge = piece_edges[e];
      if (edge.pieces_differ ^ piece_flip[numberOf(edge.piece_t)] ^
          piece_flip[numberOf(edge.piece_u)])
        conflicts_out[cross_lower_holder[e - own_edges]].push_back({edge.key, edge.t, edge.u});
    }
    std::vector<PieceTurn> turns;
    deliver(turns_out, group, [&](const PieceTurn &turn) { turns.push_back(turn); });
    std::sort(turns.begin(), turns.end(),
              [](const PieceTurn &a, const PieceTurn &b) { return a.piece < b.piece; });

    TwistsPart part;
    part.flipped.assign(count, 0);
    for (std::size_t t = 0; t < count; ++t) {
      if (!twisted(t))
        continue;
      const auto found =
          std::lower_bound(turns.begin(), turns.end(), piece[t],
                           [](const PieceTurn &turn, std::uint64_t id) { return turn.piece < id; });
      // A piece process 0 never saw is a whole component.
      const bool answered = found != turns.end() && found->piece == piece[t];
      part.flipped[t] = flip[t] ^ (answered ? found->flip : 0);
    }
    forEachEdge([&](std::size_t t, std::uint64_t u_whole) {
      if (!mineAt(u_whole))
        return;
      const auto u = static_cast<std::size_t>(u_whole - first);
      Triangle turned_t = mine[t], turned_u = mine[u];
      if (part.flipped[t])
        std::swap(turned_t[1], turned_t[2]);
      if (part.flipped[u])
        std::swap(turned_u[1], turned_u[2]);
      if (!consistentlyOriented(turned_t, turned_u))
        part.conflicts.push_back({sharedEdge(mine[t], mine[u]), first + t, u_whole});
    });
    deliver(conflicts_out, group,
            [&](const TwistConflict &conflict) { part.conflicts.push_back(conflict); });
    std::sort(part.conflicts.begin(), part.conflicts.end());
    return part;
  }
  return {}; // not reached: the second round has no flat edges to twist
}

} // namespace detail
} // namespace pcl_ms
