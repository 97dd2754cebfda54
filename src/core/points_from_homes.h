// SPDX-License-Identifier: GPL-3.0-or-later
// The points a process's triangles need, from the processes that hold them
// (docs/algorithm.md, "Finishing in parts"): each process holds a slice of
// the points (its "home" points), the slices following each other in
// process order. Internal to the library: not installed.
#pragma once

#include "process_bytes.h"

#include <pcl_ms/process_group.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace pcl_ms {
namespace detail {

/// The corners of a run of triangles and their positions (perhaps with
/// those of triangles that have left the run: addCornerPointsFromHomes).
struct CornerPoints {
  std::vector<VertexIndex> vertices; // ascending, each once
  std::vector<Eigen::Vector3d> points;

  /// The position of corner v (one of `vertices`).
  const Eigen::Vector3d &of(VertexIndex v) const;
};

/// A request for point `vertex`'s values from the process `asker`.
struct HomeRequest {
  std::uint64_t vertex;
  std::uint32_t asker;
};

/// Collective. Each process's values for `vertices` (ascending, each once,
/// all below firsts.back()) from the processes holding them: `firsts` is
/// runFirsts() of the home slices, this process's from `home_first` on,
/// and make(i) gives the value (trivially copyable) of its home item i.
template <typename Value, typename Make>
std::vector<Value>
valuesFromHomes(const std::vector<VertexIndex> &vertices, const std::vector<std::uint64_t> &firsts,
                std::uint64_t home_first, const Make &make, ProcessGroup &group) {
  const auto processes = static_cast<std::size_t>(group.processes());
  std::vector<std::vector<HomeRequest>> requests_out(processes);
  for (VertexIndex v : vertices)
    requests_out[runHolding(firsts, v)].push_back({v, static_cast<std::uint32_t>(group.process())});
  // Each home answers its askers in the order they asked; the homes hold
  // ascending ranges and answers arrive in process order, so the values
  // come back in the order of `vertices`.
  std::vector<std::vector<Value>> answers_out(processes);
  deliver(requests_out, group, [&](const HomeRequest &request) {
    answers_out[request.asker].push_back(
        make(static_cast<std::size_t>(request.vertex - home_first)));
  });
  std::vector<Value> values;
  values.reserve(vertices.size());
  deliver(answers_out, group, [&](const Value &value) { values.push_back(value); });
  return values;
}

/// Collective. `home` holds the points from number `home_first` on. Every
/// process asks the homes of its triangles' corners for them, one request
/// per distinct corner. Throws std::invalid_argument on every process when
/// the slices do not follow each other from point 0 or a corner is beyond
/// the points.
CornerPoints cornerPointsFromHomes(const std::vector<Triangle> &mine,
                                   const std::vector<Eigen::Vector3d> &home,
                                   std::uint64_t home_first, ProcessGroup &group);

/// Collective. Brings `corners` up to date for `mine`, whose triangles
/// before `first_new` have their corners in it already (kept triangles of
/// the run it was made for): only the new triangles' corners it lacks are
/// fetched. Corners of triangles gone may stay: `corners` may hold more
/// than the run's corners. Throws std::invalid_argument on every process
/// as cornerPointsFromHomes does, or for first_new beyond mine.size().
void addCornerPointsFromHomes(CornerPoints &corners, const std::vector<Triangle> &mine,
                              std::size_t first_new, const std::vector<Eigen::Vector3d> &home,
                              std::uint64_t home_first, ProcessGroup &group);

} // namespace detail
} // namespace pcl_ms
