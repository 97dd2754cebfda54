// SPDX-License-Identifier: GPL-3.0-or-later
// Plain types shared by every stage of the core. The core never sees PCL point
// types: points come in as strided float arrays, triangles go out as indices.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

namespace pcl_ms {

using VertexIndex = std::uint32_t;
using Triangle = std::array<VertexIndex, 3>;

/// A read-only list of record numbers in whichever integer type the caller
/// holds them: pcl::Indices is 32 or 64 bits, signed or not, depending on how
/// PCL was built.
class IndexList {
public:
  IndexList() = default;
  template <typename Integer>
  explicit IndexList(const std::vector<Integer> &indices)
      : data_(indices.data()), size_(indices.size()), bytes_(sizeof(Integer)),
        signed_(std::is_signed_v<Integer>), given_(true) {
    static_assert(std::is_integral_v<Integer> && (sizeof(Integer) == 4 || sizeof(Integer) == 8),
                  "indices must be 32- or 64-bit integers");
  }

  /// Whether a list was given; an empty one selects no record.
  explicit operator bool() const { return given_; }
  std::size_t size() const { return size_; }

  /// Entry i; -1 for an unsigned entry too large for int64 (it is out of any
  /// cloud's range either way).
  std::int64_t operator[](std::size_t i) const {
    if (bytes_ == 4)
      return signed_ ? std::int64_t{static_cast<const std::int32_t *>(data_)[i]}
                     : std::int64_t{static_cast<const std::uint32_t *>(data_)[i]};
    if (signed_)
      return static_cast<const std::int64_t *>(data_)[i];
    const std::uint64_t entry = static_cast<const std::uint64_t *>(data_)[i];
    const auto largest = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
    return entry > largest ? -1 : static_cast<std::int64_t>(entry);
  }

private:
  const void *data_ = nullptr;
  std::size_t size_ = 0;
  std::uint8_t bytes_ = 4;
  bool signed_ = true;
  bool given_ = false;
};

/// Read-only view of the user's points: `size` records, `stride` bytes apart,
/// each starting with three consecutive floats x, y, z (true for every PCL
/// point type, and for a plain float[3] array with stride 12).
struct PointView {
  const float *xyz = nullptr;
  std::size_t size = 0;
  std::size_t stride = 3 * sizeof(float);
  /// Optional normals, same layout rules (nx, ny, nz consecutive floats).
  const float *normals = nullptr;
  std::size_t normal_stride = 3 * sizeof(float);
  /// Optional subset of records to use (like pcl::PCLBase::setIndices);
  /// the list must outlive the call.
  IndexList indices;
};

/// How reconstruct() treats the initial triangles of a partial mesh or
/// polygon soup (docs/algorithm.md, "Initial triangles").
enum class InitialTrianglesMode : std::uint8_t {
  /// In the surface from the start and never undone; input that is not an
  /// edge-manifold set of valid triangles is rejected with the reason.
  fixed,
  /// Accepted first, cost 0, but undone like any other candidate when they
  /// conflict; duplicates are merged, invalid and oversize ones left out.
  preferred
};

/// The medial axis that the surface leaves: the A1^4 nodes (Voronoi vertices
/// of the points) that are poles with wide contacts, and the A1^3 shock
/// curves (Voronoi edges) joining two of them whose Delaunay triangle is not
/// in the surface
/// (docs/algorithm.md, "Medial axis output"). Plain arrays, one entry per node.
struct MedialAxis {
  /// Where a node lies relative to the reconstructed surface.
  enum Side : std::uint8_t {
    outside = 0, ///< outside every closed component, away from open ones
    inside = 1,  ///< enclosed by a closed component of the surface
    open = 2     ///< reachable from outside past an open component: no side
  };
  /// Node positions in the user's coordinates.
  std::vector<Eigen::Vector3d> node_positions;
  /// Radius of the maximal ball at each node (the tetrahedron's circumradius).
  std::vector<double> node_radii;
  /// A Side per node.
  std::vector<std::uint8_t> node_side;
  /// Shock curves as pairs of node indices, the smaller first, sorted.
  std::vector<std::array<std::uint32_t, 2>> curves;
};

/// All tuning knobs of the method (docs/algorithm.md).
struct Parameters {
  /// Candidates with a side >= rho times their local scale (the typical
  /// circumradius of the surface triangles where they lie; on a uniform
  /// sample about d_med) are never queued.
  /// 5, the low end of the paper's 5-15: on the Stanford bunny, 10 already
  /// bridges the two large base holes that the paper leaves open (1.5 % of
  /// the diagonal off the reference surface, against 0.5 % at 5, same recall).
  double rho = 5.0;
  /// Close boundary loops of at most this many edges (0 = off). The greedy
  /// leaves a few tiny loops where its vertex rules refused the last
  /// triangle; 8 closes them on the bunny and leaves real openings alone.
  int fill_holes_max_edges = 8;
  /// Where a one-view scan was taken from (the cloud's coordinates): every
  /// component that has a boundary is then oriented to face it, and any
  /// twist in it is repaired, since a surface seen from one point is never
  /// one-sided. Closed components stay oriented outward.
  std::optional<std::array<double, 3>> viewpoint;
  /// Use the input normals to prefer candidates aligned with them.
  bool use_normals = false;
  /// kappa in eps1 * (1 + kappa (1 - mean |n_T . n_v|)).
  double normal_weight = 1.0;
  /// Relative cost gap under which two competing candidates are delayed.
  double close_ranking_tolerance = 0.05;
  /// Factor applied to a delayed candidate's cost.
  double delay_factor = 1.2;
  /// Delays per candidate before it is decided anyway.
  int max_delays = 5;
  /// Undo accepted triangles whose cost grew above a conflicting candidate's.
  bool error_recovery = true;
  /// Worker threads for the parallel stages; 0 = all cores. Never changes the result.
  int num_threads = 1;
  /// A cloud meshed in one piece with fewer points than this uses one
  /// thread whatever num_threads says: below it, starting the threads cost
  /// more than they saved (docs/algorithm.md, "Threads"). 0 = always
  /// num_threads.
  std::size_t min_points_for_threads = 5000;
  /// Large clouds are meshed in buckets of about this many points that are
  /// stitched together (paper §4). 0 = automatic: buckets of
  /// default_bucket_points above automatic_bucketing_threshold points, one
  /// piece below (buckets.h). A cloud no larger than this is one piece.
  std::size_t bucket_points = 0;
  /// > 0: cut the bounding box into grid_buckets^3 equal buckets instead.
  int grid_buckets = 0;
  /// Seconds after which reconstruct() gives up with TimeLimitExceeded (a
  /// ReconstructionError) and no mesh; 0 = no limit.
  double time_limit_seconds = 0;
  /// Called with (units done, units in all) as buckets and seams finish,
  /// from worker threads one call at a time.
  std::function<void(std::size_t, std::size_t)> progress;
  /// How initial triangles given to reconstruct() are treated (default fixed).
  InitialTrianglesMode initial_triangles_mode = InitialTrianglesMode::fixed;
  /// Also compute the medial axis the surface leaves (Result::medial_axis).
  /// Off by default: it builds a Delaunay triangulation of its own.
  bool compute_medial_axis = false;
  /// Non-manifold seams (docs/algorithm.md, "Seams (opt-in)"): after pass 2 a
  /// third pass may put a third (fourth...) triangle on an edge where sheets
  /// meet. Off by default: the output is then 2-manifold. A cloud is meshed in
  /// one piece when it is on, whatever its size: the bucket units do not
  /// look for seams.
  bool allow_non_manifold = false;

  /// Empty when valid, else a one-line reason.
  std::string validate() const;
};

/// What one greedy pass did.
struct PassStatistics {
  std::size_t popped = 0;
  std::size_t accepted = 0;
  std::size_t undone = 0;
  std::size_t delayed = 0;
  std::size_t rejected = 0;
  std::size_t demoted = 0;
};

/// What the bucketed path did (all zero when the cloud was one piece).
struct BucketStatistics {
  std::size_t buckets = 0;
  std::size_t margin_points = 0; // points meshed again as some bucket's margin
  std::size_t seam_zones = 0;
  std::size_t seam_points = 0;               // points in all seam zones together
  std::size_t seam_triangles = 0;            // triangles the seams added
  std::size_t failed_units = 0;              // buckets or zones left empty (e.g. collinear points)
  std::size_t bow_tie_triangles_removed = 0; // smaller fans where seams met
  // Wall clock. In one process zones run beside the buckets: buckets_seconds
  // ends with the last bucket, seams_seconds is what follows it.
  double buckets_seconds = 0;
  double seams_seconds = 0;
};

/// Wall-clock seconds per stage. In bucketed runs delaunay, scaffold and
/// greedy are summed over buckets and seams (thread time, not wall clock).
struct StageTimings {
  double prepare = 0;     // validation, NaN and duplicate removal
  double delaunay = 0;    // Delaunay tetrahedralisation
  double scaffold = 0;    // candidates, types, costs, candidate graph
  double greedy = 0;      // passes 1 and 2 with clean-up
  double finish = 0;      // manifold sweep, holes, orientation, loops
  double medial_axis = 0; // only when Parameters::compute_medial_axis
  double total = 0;
};

/// The process's peak resident memory (bytes) when each stage ended, so the
/// growth from one to the next is what that stage needed at most. 0 where
/// the platform does not report it (read from /proc on Linux).
struct StagePeakMemory {
  std::size_t prepare = 0;
  std::size_t scaffold = 0; // Delaunay structure and candidates
  std::size_t greedy = 0;
  std::size_t finish = 0;
};

/// Everything the core reports after a run. Indices refer to the user's
/// records (PointView::xyz), never to a filtered copy.
struct Result {
  std::vector<Triangle> triangles;
  /// Closed boundary curves, each a cyclic list of vertex indices.
  std::vector<std::vector<VertexIndex>> boundary_loops;
  /// Connected component of each triangle (by shared edges), 0-based.
  std::vector<std::uint32_t> triangle_component;
  /// One flag per component: false where no consistent orientation exists.
  std::vector<bool> component_orientable;

  std::size_t input_points = 0;     // records considered (after indices)
  std::size_t invalid_points = 0;   // NaN / Inf, skipped
  std::size_t duplicate_points = 0; // exact repeats, merged onto the first
  std::size_t used_points = 0;      // distinct points that went into the scaffold
  /// Stray points farther from the rest than the cloud's own size, with no
  /// other point near them: no surface can reach them, so they are left out
  /// of the scaffold (and stay unreferenced vertices of the cloud).
  std::size_t far_points = 0;
  bool planar = false; // all points on one plane: 2-D Delaunay used

  std::size_t candidates_type1 = 0, candidates_type2 = 0, candidates_type3 = 0;
  std::size_t candidates_oversize = 0;
  /// Delaunay triangles whose corners are collinear, or so unevenly far
  /// apart that their circumcircle does not exist in double precision
  /// (left out). Exact predicates keep the collinear ones at 0.
  std::size_t candidates_degenerate = 0;
  /// Summaries: the median Gabriel circumradius and rho times it. The size
  /// limit itself is local (Parameters::rho).
  double d_med = 0, d_max = 0;
  PassStatistics pass1, pass2;
  std::size_t cleanup_undone = 0; // flaps/isolated triangles and final sweep
  std::size_t swapped_pairs = 0;  // non-Delaunay quads re-triangulated
  std::size_t holes_filled = 0;
  /// Triangles cut out where the surface folded or twisted (the finish's
  /// twist repair; docs/algorithm.md, "Finishing").
  std::size_t twist_triangles_removed = 0;
  /// Initial triangles (preferred mode) left out before meshing: listed
  /// again (any corner order; merged), invalid (a point that is not a valid
  /// input point, two corners at one position, or all three on a line), or
  /// oversize (a side reaching rho times the local scale).
  std::size_t initial_duplicates = 0, initial_invalid = 0, initial_oversize = 0;
  /// Distinct initial triangles that are in the output mesh (either mode).
  std::size_t initial_kept = 0;
  /// With Parameters::allow_non_manifold: the edges that hold three or more
  /// triangles (user indices, smaller first, sorted), and how many triangles
  /// joined the finished surface along the seams: those on seam edges and
  /// the seam pass's fillers (they are in `triangles` too).
  std::vector<std::array<VertexIndex, 2>> seam_edges;
  std::size_t seam_triangles = 0;
  BucketStatistics bucket_statistics;
  /// Only with Parameters::compute_medial_axis (and on process 0).
  std::optional<MedialAxis> medial_axis;
  StageTimings timings;
  StagePeakMemory peak_memory;

  std::size_t numberOfComponents() const { return component_orientable.size(); }
  std::size_t numberOfNonOrientableComponents() const;
};

} // namespace pcl_ms
