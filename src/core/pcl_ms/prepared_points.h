// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 1's result (docs/algorithm.md section 1), and the preparation of a
// cloud whose records are spread over processes ("Across processes"): each
// prepares its part together with the others and ends with its slice of
// the points in the order one process would give them.
#pragma once

#include <pcl_ms/buckets.h>
#include <pcl_ms/deadline.h>
#include <pcl_ms/finish.h>
#include <pcl_ms/process_group.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace pcl_ms {

/// PreparedPoints::prepared_of_record's entry for a record left out.
constexpr VertexIndex not_prepared = std::numeric_limits<VertexIndex>::max();

/// The distinct, finite points of the user's records, centred, in Morton
/// order, and for each the user record it stands for.
struct PreparedPoints {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3f> normals; // unit or zero; empty unless asked for
  std::vector<VertexIndex> user_index;
  /// Subtracted from the user's coordinates.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  /// For each user record, its distinct point (duplicates share one), or
  /// not_prepared for records left out (NaN/Inf, not in the indices). Only
  /// built when asked for: initial triangles need it.
  std::vector<VertexIndex> prepared_of_record;
};

/// What the preparation counted, over the whole cloud.
struct PreparationCounts {
  std::size_t input_points = 0, invalid_points = 0, duplicate_points = 0, far_points = 0;
};

/// Stage 1 in one process: the distinct finite points of `view`, far stray
/// points left out; fills result's counts. `map_records` builds
/// prepared_of_record. Throws ReconstructionError for fewer than 3 points.
PreparedPoints preparePoints(const PointView &view, bool with_normals, bool map_records,
                             Result &result);

/// The error for a cloud with fewer than 3 distinct points, with its counts.
std::string tooFewPoints(const PreparationCounts &counts, std::size_t distinct);

/// One process's slice of the prepared points: `points` are the distinct
/// points [first, first + points.positions.size()) of the `total` that one
/// process preparing the whole cloud would have; centre and counts are the
/// whole cloud's.
struct PreparedSlice {
  PreparedPoints points;
  std::size_t first = 0, total = 0;
  PreparationCounts counts;
};

/// Prepares the records `part` (no indices) whose first is the cloud's
/// record `first_record`, together with the other processes of `group`,
/// each with its own consecutive records. Collective. Throws
/// ReconstructionError, on every process alike, when the cloud has fewer
/// than 3 distinct finite points or more records than 32-bit indices hold.
PreparedSlice preparePointsTogether(const PointView &part, std::uint64_t first_record,
                                    bool with_normals, ProcessGroup &group);

/// A process's run of the finished surface, left where it was finished
/// (reconstructSlices' `runs`): the whole list is the runs in process
/// order, the same list as Result::triangles, in the user's records.
struct FinishedRun {
  bool used = false; // the same on every process: the surface is in the runs
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> component; // as Result::triangle_component
  std::uint64_t first = 0;              // the number of triangles[0] in the whole list
  std::uint64_t total = 0;              // triangles in the whole list
};

/// What meshSlicesInBuckets gives: on process 0, the finished surface in
/// the prepared order's numbers and the points' records in the user's
/// cloud (`points.user_index`; their positions too when the medial axis is
/// asked for); on every process, the buckets' figures and times
/// (`surface`, without triangles). In runs (`in_runs`), process 0 has the
/// loops in the user's records and no triangles or points: every process
/// has its run.
struct SharedSurface {
  PreparedPoints points;
  BucketedSurface surface;
  FinishedSurface finished;
  FinishedRun run;
  double finish_seconds = 0;
};

/// Meshes in buckets the points of all processes' slices, each process
/// meshing the buckets it owns (bucketOwner) and the seam zones whose first
/// bucket it owns, with the points those need sent to it, then finishes the
/// surface with the triangles in runs over the processes
/// (detail::finishInParts): no process holds all the points or all the
/// triangles, unless process 0 receives the finished triangles at the end
/// (`in_runs` false, or the medial axis).
/// The same surface as meshInBuckets then finishSurface on the joined
/// points. Collective.
SharedSurface meshSlicesInBuckets(const PreparedSlice &slice, const Parameters &parameters,
                                  const Deadline *deadline, ProcessGroup &group,
                                  bool in_runs = false);

/// Process 0 gets all processes' slices joined in process order (the
/// prepared order); the others get nothing. Collective.
PreparedPoints joinSlicesAtProcessZero(const PreparedPoints &slice, bool with_normals,
                                       ProcessGroup &group);

/// reconstruct() for the slices of preparePointsTogether: a bucketed cloud
/// is meshed by meshSlicesInBuckets, one piece by process 0 alone; process
/// 0 finishes the surface and gets the result, the others the preparation's
/// and the buckets' figures and no triangles. Given `runs`, a bucketed
/// cloud without the medial axis leaves the triangles in runs
/// (`runs->used` on every process): process 0's result then has no
/// triangles or triangle components, so that no process holds the whole
/// surface. Collective.
Result reconstructSlices(PreparedSlice &&slice, const Parameters &parameters, ProcessGroup &group,
                         FinishedRun *runs = nullptr);

} // namespace pcl_ms
