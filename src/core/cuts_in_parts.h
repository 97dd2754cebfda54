// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4's cut of the twist repair's triangles and the bow-tie split after
// it, for a triangle list held in parts by the processes of a ProcessGroup
// (docs/algorithm.md, "Finishing in parts"). In: each process's run of the
// list and the triangles to cut. Out: the runs without them and without
// the bow-ties' smaller fans, and the corners of what went.
// Internal to the library: not installed.
#pragma once

#include <pcl_ms/process_group.h>
#include <pcl_ms/types.h>

#include <cstdint>
#include <vector>

namespace pcl_ms {
namespace detail {

/// What cutInParts() leaves each process.
struct CutPart {
  /// The process's run without the triangles that went, in order; it
  /// starts at whole-list number `first` of the list they leave.
  std::vector<Triangle> kept;
  std::uint64_t first = 0;
  /// The corners of the process's triangles that went (ascending, each
  /// once): together, the vertices one process marks `touched`.
  std::vector<VertexIndex> touched;
  /// On every process: the bow-ties' triangles that went, of the whole list.
  std::uint64_t split_off = 0;
  /// The places in the process's run of the triangles that went (cut or
  /// split off), ascending: what dropFromEdgesInParts() takes.
  std::vector<std::size_t> dropped;
};

/// Collective. `mine` is this process's run of the list, from whole-list
/// number `first` on (the runs follow each other in process order);
/// `to_cut` whole-list numbers of triangles to cut, given on any process;
/// `also_check` vertices (ascending, each once) whose fans are checked in
/// the first round besides the cut's corners (after the buckets: the seams'
/// points, as one process's splitBowTies() is given them).
/// The same as one process's dropTriangles() then splitBowTies() without
/// fixed triangles (the tool meshes clouds with initial triangles on one
/// process): each round, the triangles at the vertices to check go to
/// process v mod processes with their numbers in the list the cut leaves,
/// which groups them into fans as one process does and sends back those to
/// go. Throws
/// std::invalid_argument on every process when the runs do not follow each
/// other from 0 or a number to cut is beyond the list.
CutPart cutInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                   const std::vector<std::uint64_t> &to_cut, ProcessGroup &group,
                   const std::vector<VertexIndex> &also_check = {});

} // namespace detail
} // namespace pcl_ms
