// SPDX-License-Identifier: GPL-3.0-or-later
// Stage for large clouds (paper §4): the cloud is cut into buckets, each
// meshed with a margin of its neighbours' points; the triangles inside a
// bucket are kept, and the zones along the cuts are meshed again with the
// kept triangles around them fixed. Buckets and zones are independent units
// of work (points in, triangles out), run in parallel.
#pragma once

#include <pcl_ms/deadline.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace pcl_ms {

/// Target bucket size when Parameters::bucket_points is 0 (automatic).
constexpr std::size_t default_bucket_points = 100000;
/// Clouds above this many distinct points are meshed in buckets by default.
constexpr std::size_t automatic_bucketing_threshold = 600000;

/// Smaller buckets would be mostly margin.
constexpr std::size_t min_bucket_points = 1000;
/// grid_buckets^3 buckets at most.
constexpr int max_grid_buckets = 64;

/// One self-contained unit of work: a bucket with its margin, or a seam
/// zone. Indices are local to `points`.
struct BucketTask {
  std::vector<Eigen::Vector3d> points;
  /// Empty, or one unit normal per point (used when Parameters::use_normals).
  std::vector<Eigen::Vector3f> normals;
  /// Triangles are kept only when all three vertices are core points; the
  /// others are margin, there to give the core the right neighbourhood.
  std::vector<bool> core;
  /// Triangles already in the surface; they stay and are not returned.
  std::vector<Triangle> fixed_triangles;
  /// Points that only fixed triangles may use (empty: none).
  std::vector<bool> frozen;
  /// d_med to report (> 0), or 0 to measure it on these points.
  double d_med = 0;
  /// Empty, or a local scale per point: entries > 0 are used as they are,
  /// the others measured here (see ScaffoldOptions::local_scale).
  std::vector<float> local_scale;
};

struct BucketOutcome {
  std::vector<Triangle> triangles; // new triangles on core points, local indices
  /// Core points that lost a triangle because another of its corners was
  /// not core: where the kept triangles may pinch, ascending.
  std::vector<VertexIndex> cut_vertices;
  double d_med = 0;
  /// The local scale of each point of the task (empty on error).
  std::vector<float> local_scale;
  double delaunay_seconds = 0, scaffold_seconds = 0, greedy_seconds = 0;
  /// Not empty when the unit could not be meshed (e.g. collinear points).
  std::string error;
};

/// Scaffold and greedy passes on one unit (no hole filling or orientation:
/// those run once on the whole surface). Single-threaded. A passed deadline
/// throws TimeLimitExceeded instead of failing the unit.
BucketOutcome meshBucket(const BucketTask &task, const Parameters &parameters,
                         const Deadline *deadline = nullptr);

/// Whether reconstruct() meshes `points` distinct points in buckets.
bool usesBuckets(std::size_t points, const Parameters &parameters);

struct BucketedSurface {
  std::vector<Triangle> triangles; // indices into the points given
  double d_med = 0;                // median of the buckets' d_med
  /// Each point's local scale, as measured by the bucket that owns it.
  std::vector<float> local_scale;
  BucketStatistics statistics;
  // Summed over buckets and seams (thread time).
  double delaunay_seconds = 0, scaffold_seconds = 0, greedy_seconds = 0;
};

/// Meshes units somewhere else (docs/algorithm.md, "Across processes"):
/// the process that plans the buckets and seams builds each unit's task and
/// hands it out, so whoever meshes it holds that unit's points only.
class UnitFarm {
public:
  virtual ~UnitFarm() = default;
  /// Meshes units 0 .. count - 1: make(i) gives unit i's task, done(i, o)
  /// takes meshBucket's outcome for it. Both are called on the calling
  /// thread, make(i) before done(i), in any order over i; few units are
  /// in flight at once.
  virtual void mesh(std::size_t count, const std::function<BucketTask(std::size_t)> &make,
                    const std::function<void(std::size_t, BucketOutcome &&)> &done) = 0;
};

/// Shares the buckets and seam zones of meshInBuckets among cooperating
/// processes that all hold the same points (docs/algorithm.md, "Across
/// processes"). The default is one process doing everything. Process r owns
/// a contiguous range of leaves (bucketOwner) and every zone whose first
/// leaf it owns, so process 0 owns the root and ends up with the whole
/// surface. Every call is collective: all processes make it, in the same
/// order.
class BucketExchange {
public:
  virtual ~BucketExchange() = default;
  virtual int processes() const { return 1; }
  virtual int process() const { return 0; }
  /// Element-wise maximum (scales: owners have them, the others 0).
  virtual void maxOver(std::vector<float> &) {}
  virtual void maxOver(std::vector<std::uint8_t> &) {}
  /// Element-wise sum (per-unit figures: only the owner's is non-zero).
  virtual void sumOver(std::vector<double> &) {}
  struct Transfer {
    int from = 0, to = 0;
    std::vector<Triangle> *triangles = nullptr; // sent from `from`, then emptied there
  };
  /// Moves each transfer's triangles from its sender to its receiver.
  virtual void moveTriangles(const std::vector<Transfer> &) {}
  /// Called on every process after the buckets and after each seam level.
  virtual void stageDone(const std::string & /*stage*/) {}
  /// Called once reconstruct() has prepared its points: it reads the
  /// PointView no more, so the memory the view points into may be freed.
  virtual void pointsPrepared() {}
  /// Not null: this (single) process plans every unit and the farm meshes
  /// them, instead of sharing them by owner as above.
  virtual UnitFarm *farm() { return nullptr; }
};

/// The process that meshes leaf number `leaf` of `leaves`.
inline int bucketOwner(std::size_t leaf, std::size_t leaves, int processes) {
  return static_cast<int>(leaf * static_cast<std::size_t>(processes) / leaves);
}

/// Meshes the points in buckets and stitches them. `normals` is null or has
/// one entry per point. The result does not depend on the thread count, nor
/// on how `exchange` shares the work; with several processes only process 0
/// gets the triangles (the others' are empty).
BucketedSurface meshInBuckets(const std::vector<Eigen::Vector3d> &points,
                              const std::vector<Eigen::Vector3f> *normals,
                              const Parameters &parameters, const Deadline *deadline = nullptr,
                              BucketExchange *exchange = nullptr);

} // namespace pcl_ms
