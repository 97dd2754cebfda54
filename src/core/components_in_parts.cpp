// SPDX-License-Identifier: GPL-3.0-or-later
// Components and consistent orientation over a triangle list held in parts
// (components_in_parts.h; docs/algorithm.md, "Finishing in parts").
#include "components_in_parts.h"

#include "finish_steps.h"
#include "pieces_in_parts.h"
#include "process_bytes.h"

#include <pcl_ms/disjoint_sets.h>

#include <algorithm>
#include <utility>

namespace pcl_ms {
namespace detail {
namespace {

/// One side of an edge between two runs, sent to process 0: the triangle
/// on this side, the one across, and the piece of this run it belongs to
/// (the piece's first triangle, the triangle's turn relative to it,
/// whether the piece holds a cycle that reverses orientation).
struct CrossSide {
  std::uint64_t triangle;
  std::uint64_t across;
  std::uint64_t piece;
  Triangle corners;
  std::uint32_t process;
  std::uint8_t flip;
  std::uint8_t conflicted;
};

/// Process 0's answer for a piece: its component's first triangle, the
/// piece's turn relative to it, and whether the component is orientable.
struct PieceAnswer {
  std::uint64_t piece;
  std::uint64_t component;
  std::uint8_t flip;
  std::uint8_t orientable;
};

/// Process 0's part: joins the pieces along the edges between runs and
/// answers every piece that has such an edge, to its process.
std::vector<std::vector<PieceAnswer>> joinPieces(std::vector<CrossSide> &sides,
                                                 std::size_t processes) {
  std::vector<std::vector<PieceAnswer>> answers(processes);
  if (sides.empty())
    return answers;
  // The pieces numbered, joined along the edges between them.
  std::vector<std::uint64_t> named;
  named.reserve(sides.size());
  for (const CrossSide &side : sides)
    named.push_back(side.piece);
  const PieceNumbers numberOf(std::move(named));
  ParityForest forest(numberOf.size());
  std::vector<std::uint8_t> conflicted(numberOf.size(), 0);
  for (const CrossSide &side : sides)
    conflicted[numberOf(side.piece)] |= side.conflicted;
  forEachTrianglePair(sides, [&](std::size_t begin, std::size_t end) {
    const CrossSide &low = sides[begin], &high = sides[end - 1];
    if (low.triangle == high.triangle)
      return;
    // t = low's triangle, u = high's: u's piece flipped by `flip` relative
    // to t's must differ from t's by whether they disagree, as stored.
    const bool must_differ = !consistentlyOriented(low.corners, high.corners);
    const auto t = numberOf(low.piece), u = numberOf(high.piece);
    if (forest.join(t, u, must_differ != (low.flip != high.flip)) == ParityForest::Join::conflict)
      conflicted[t] = 1;
  });
  std::vector<std::uint8_t> component_conflicted(numberOf.size(), 0);
  for (std::uint32_t p = 0; p < numberOf.size(); ++p)
    component_conflicted[forest.find(p).first] |= conflicted[p];
  // One answer per piece, to each process that sent a side of it.
  std::vector<std::uint8_t> answered(numberOf.size() * processes, 0);
  for (const CrossSide &side : sides) {
    const std::uint32_t p = numberOf(side.piece);
    std::uint8_t &done = answered[std::size_t{p} * processes + side.process];
    if (done)
      continue;
    done = 1;
    const auto [root, flip] = forest.find(p);
    answers[side.process].push_back({side.piece, numberOf.id(root), flip,
                                     static_cast<std::uint8_t>(!component_conflicted[root])});
  }
  return answers;
}

} // namespace

ComponentsPart componentsInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                                 const MeshEdgesPart &edges, ProcessGroup &group) {
  const std::size_t count = mine.size();
  const auto mineAt = [&](std::uint64_t triangle) {
    return triangle >= first && triangle - first < count;
  };
  // The run's own pieces: its edges within the run joined in a parity
  // forest, whose roots are the pieces' first triangles.
  ParityForest forest(count);
  std::vector<std::uint8_t> conflicted(count, 0);
  for (std::size_t t = 0; t < count; ++t)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint64_t u = edges.neighbours[3 * t + k];
      if (u == no_neighbour_in_parts || !mineAt(u) || u - first <= t)
        continue;
      const auto local = static_cast<std::uint32_t>(u - first);
      if (forest.join(static_cast<std::uint32_t>(t), local,
                      !consistentlyOriented(mine[t], mine[local])) == ParityForest::Join::conflict)
        conflicted[t] = 1;
    }
  ComponentsPart part;
  part.component.resize(count);
  part.flipped.resize(count);
  part.orientable.assign(count, 1);
  for (std::size_t t = 0; t < count; ++t) {
    const auto [root, flip] = forest.find(static_cast<std::uint32_t>(t));
    part.component[t] = first + root;
    part.flipped[t] = flip;
    if (conflicted[t])
      part.orientable[root] = 0; // read through the root below
  }
  for (std::size_t t = 0; t < count; ++t)
    part.orientable[t] = part.orientable[part.component[t] - first];

  // The edges between runs, a side from each run, to process 0.
  const auto processes = static_cast<std::size_t>(group.processes());
  std::vector<std::vector<CrossSide>> sides_out(processes);
  for (std::size_t t = 0; t < count; ++t)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint64_t u = edges.neighbours[3 * t + k];
      if (u != no_neighbour_in_parts && !mineAt(u))
        sides_out[0].push_back({first + t, u, part.component[t], mine[t],
                                static_cast<std::uint32_t>(group.process()), part.flipped[t],
                                static_cast<std::uint8_t>(!part.orientable[t])});
    }
  std::vector<CrossSide> sides;
  deliver(sides_out, group, [&](const CrossSide &side) { sides.push_back(side); });
  std::vector<std::vector<PieceAnswer>> answers_out = joinPieces(sides, processes);
  std::vector<CrossSide>().swap(sides);
  std::vector<PieceAnswer> answers;
  deliver(answers_out, group, [&](const PieceAnswer &answer) { answers.push_back(answer); });
  std::sort(answers.begin(), answers.end(),
            [](const PieceAnswer &a, const PieceAnswer &b) { return a.piece < b.piece; });
  for (std::size_t t = 0; t < count; ++t) {
    const auto found = std::lower_bound(
        answers.begin(), answers.end(), part.component[t],
        [](const PieceAnswer &answer, std::uint64_t piece) { return answer.piece < piece; });
    if (found == answers.end() || found->piece != part.component[t])
      continue;
    part.component[t] = found->component;
    part.flipped[t] ^= found->flip;
    part.orientable[t] = found->orientable;
  }
  return part;
}

} // namespace detail
} // namespace pcl_ms
