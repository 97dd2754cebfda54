// SPDX-License-Identifier: GPL-3.0-or-later
// pcl::MedialScaffoldReconstruction: a PCL surface-reconstruction class over
// the pcl_ms core (medial-scaffold gap transforms, Leymarie/Chang/Kimia).
#pragma once

#include <pcl_ms/types.h>

#include <pcl/PolygonMesh.h>
#include <pcl/Vertices.h>
#include <pcl/point_cloud.h>
#include <pcl/surface/reconstruction.h>

#include <string>
#include <vector>

namespace pcl {

/** \brief Interpolating surface reconstruction by greedy gap transforms on
 * the medial scaffold (Delaunay triangles ranked by shape and shock-curve
 * length, accepted under 2-manifold rules, with error recovery).
 *
 * Handles open surfaces with boundaries, non-orientable surfaces, sharp
 * features and uneven sampling; needs no normals. The output mesh's cloud is
 * the input cloud with all its fields and the polygons index it directly.
 *
 * \code
 * pcl::MedialScaffoldReconstruction<pcl::PointXYZ> msr;
 * msr.setInputCloud(cloud);
 * pcl::PolygonMesh mesh;
 * msr.reconstruct(mesh);
 * \endcode
 */
template <typename PointInT>
class MedialScaffoldReconstruction : public SurfaceReconstruction<PointInT> {
public:
  using Ptr = shared_ptr<MedialScaffoldReconstruction<PointInT>>;
  using ConstPtr = shared_ptr<const MedialScaffoldReconstruction<PointInT>>;
  using NormalCloud = pcl::PointCloud<pcl::Normal>;
  using InitialTrianglesMode = pcl_ms::InitialTrianglesMode;

  using SurfaceReconstruction<PointInT>::reconstruct;

  MedialScaffoldReconstruction();

  /** \brief Guarded: reports an error and returns an empty mesh when no input
   * was set (PCL's base class would dereference a null cloud). */
  void reconstruct(pcl::PolygonMesh &output) override;
  void reconstruct(pcl::PointCloud<PointInT> &points,
                   std::vector<pcl::Vertices> &polygons) override;

  /** \brief Triangle sides stay below rho times the local scale where the
   * triangle lies: the typical circumradius of the surface triangles there,
   * so sparse parts of a cloud get larger triangles than dense ones (default
   * 5; the paper uses 5-15, 30 closes the bunny's base holes). Must be > 0. */
  void setRho(double rho) { parameters_.rho = rho; }
  double getRho() const { return parameters_.rho; }

  /** \brief Close boundary loops of at most \a max_edges edges with Delaunay
   * triangles of the loop's points (default 8; 0 = off, else >= 3). */
  void setFillHoles(int max_edges) { parameters_.fill_holes_max_edges = max_edges; }
  int getFillHoles() const { return parameters_.fill_holes_max_edges; }

  /** \brief Use normals to prefer candidates aligned with them (default
   * off). Normals come from setInputNormals, else from the point type. */
  void setUseNormals(bool use) { parameters_.use_normals = use; }
  bool getUseNormals() const { return parameters_.use_normals; }

  /** \brief Non-manifold seams (default off): lines where three or more
   * sheets of candidates meet are found before the greedy passes and kept as
   * edges, and a seam pass after pass 2 puts one triangle per sheet on them
   * (docs/algorithm.md, "Seams"). Orientation is then per manifold sheet and
   * the result's seam_edges lists those edges. Off, the output is
   * 2-manifold. On, the cloud is meshed in one piece whatever its size. */
  void setAllowNonManifold(bool allow) { parameters_.allow_non_manifold = allow; }
  bool getAllowNonManifold() const { return parameters_.allow_non_manifold; }

  /** \brief Weight kappa of the normal term (default 1). Must be >= 0. */
  void setNormalWeight(double kappa) { parameters_.normal_weight = kappa; }
  double getNormalWeight() const { return parameters_.normal_weight; }

  /** \brief Normals for the input cloud, one per point (same size). */
  void setInputNormals(const NormalCloud::ConstPtr &normals) { normals_ = normals; }
  NormalCloud::ConstPtr getInputNormals() const { return normals_; }

  /** \brief Relative cost gap under which competitors are delayed (default
   * 0.05). In [0, 1). */
  void setCloseRankingTolerance(double tolerance) {
    parameters_.close_ranking_tolerance = tolerance;
  }
  double getCloseRankingTolerance() const { return parameters_.close_ranking_tolerance; }

  /** \brief Cost factor of a delay (default 1.2, must be > 1) and number of
   * delays per candidate before it is decided anyway (default 5, >= 0). */
  void setDelayFactor(double factor) { parameters_.delay_factor = factor; }
  double getDelayFactor() const { return parameters_.delay_factor; }
  void setMaxDelays(int delays) { parameters_.max_delays = delays; }
  int getMaxDelays() const { return parameters_.max_delays; }

  /** \brief Undo accepted triangles that later turn out costlier than a
   * conflicting candidate (default on). */
  void setErrorRecovery(bool enabled) { parameters_.error_recovery = enabled; }
  bool getErrorRecovery() const { return parameters_.error_recovery; }

  /** \brief Threads for the parallel stages (default 1, 0 = all cores). The
   * mesh does not depend on it. A cloud of fewer than
   * pcl_ms::Parameters::min_points_for_threads points (5,000) meshed in one
   * piece uses one thread: there the threads' start costs more than they save. */
  void setNumberOfThreads(int threads) { parameters_.num_threads = threads; }
  int getNumberOfThreads() const { return parameters_.num_threads; }

  /** \brief Mesh clouds larger than this in buckets of about this many
   * points, stitched together (default 0 = automatic: buckets of
   * pcl_ms::default_bucket_points above pcl_ms::automatic_bucketing_threshold
   * points). A value at least the cloud's size meshes it in one piece. */
  void setBucketSize(std::size_t points) { parameters_.bucket_points = points; }
  std::size_t getBucketSize() const { return parameters_.bucket_points; }

  /** \brief Cut the bounding box into n x n x n buckets instead (default 0:
   * off). */
  void setGridBuckets(int n) { parameters_.grid_buckets = n; }
  int getGridBuckets() const { return parameters_.grid_buckets; }

  /** \brief Where the cloud was scanned from, in its coordinates: every
   * component with a boundary is oriented to face it, and twists in it are
   * repaired (a surface seen from one point is never one-sided). Without it,
   * the cloud's sensor_origin_ is used when the cloud is organized (a depth
   * frame) or its sensor origin is not zero, unless setUseSensorOrigin(false). */
  void setViewpoint(float x, float y, float z) { parameters_.viewpoint = {{x, y, z}}; }
  /** \brief Forgets a viewpoint given with setViewpoint(). */
  void clearViewpoint() { parameters_.viewpoint.reset(); }
  /** \brief False when no viewpoint was given with setViewpoint(). */
  bool getViewpoint(float &x, float &y, float &z) const {
    if (!parameters_.viewpoint)
      return false;
    x = static_cast<float>((*parameters_.viewpoint)[0]);
    y = static_cast<float>((*parameters_.viewpoint)[1]);
    z = static_cast<float>((*parameters_.viewpoint)[2]);
    return true;
  }
  /** \brief Whether an organized cloud's or a non-zero sensor_origin_ serves
   * as the viewpoint when none was set (default true). */
  void setUseSensorOrigin(bool use) { use_sensor_origin_ = use; }
  bool getUseSensorOrigin() const { return use_sensor_origin_; }
  /// Gives up after this many seconds: reconstruct() then yields no mesh and
  /// getErrorMessage() says so. 0 (default) = no limit.
  void setTimeLimit(double seconds) { parameters_.time_limit_seconds = seconds; }
  double getTimeLimit() const { return parameters_.time_limit_seconds; }

  /** \brief Triangles (indices into the input cloud) of a partial mesh or
   * polygon soup; the method completes the mesh around them (default: none).
   * See setInitialTrianglesMode() for how they are treated. */
  void setInitialTriangles(const std::vector<pcl::Vertices> &triangles) {
    initial_triangles_ = triangles;
  }
  const std::vector<pcl::Vertices> &getInitialTriangles() const { return initial_triangles_; }

  /** \brief InitialTrianglesMode::fixed (default): the initial triangles stay
   * whatever happens; they must be edge-manifold triangles of valid points,
   * or reconstruct() fails with the reason (where they meet at a vertex only
   * and the surface does not join them, that vertex stays a pinch).
   * InitialTrianglesMode::preferred:
   * they are accepted first but undone like any other candidate where they
   * conflict, so that a soup with wrong, overlapping or repeated triangles
   * gives a manifold mesh; repeated ones are merged, and invalid polygons
   * (not 3 vertices, an invalid point) and oversize ones are left out and
   * counted in getResult(). */
  void setInitialTrianglesMode(InitialTrianglesMode mode) {
    parameters_.initial_triangles_mode = mode;
  }
  InitialTrianglesMode getInitialTrianglesMode() const {
    return parameters_.initial_triangles_mode;
  }

  /** \brief Also compute the medial axis the surface leaves (default off;
   * it costs a second Delaunay triangulation, nothing when off). */
  void setComputeMedialAxis(bool compute) { parameters_.compute_medial_axis = compute; }
  bool getComputeMedialAxis() const { return parameters_.compute_medial_axis; }

  /** \brief The medial axis of the last reconstruct() when
   * setComputeMedialAxis(true) was set, else empty: node positions (input
   * coordinates), ball radii, a side per node (pcl_ms::MedialAxis::Side:
   * inside or outside a closed component, or open) and curves as pairs of
   * node indices. */
  const pcl_ms::MedialAxis &getMedialScaffold() const {
    static const pcl_ms::MedialAxis none;
    return result_.medial_axis ? *result_.medial_axis : none;
  }

  /** \brief All parameters at once (core struct). */
  void setParameters(const pcl_ms::Parameters &parameters) { parameters_ = parameters; }
  const pcl_ms::Parameters &getParameters() const { return parameters_; }

  /** \brief Details of the last reconstruct(): boundary loops, components
   * and their orientability, counts per pass, timings per stage. */
  const pcl_ms::Result &getResult() const { return result_; }
  /** \brief Boundary loops of the last result, as indices into the input. */
  std::vector<pcl::Vertices> getBoundaryLoops() const;
  /** \brief Empty after a successful reconstruct(), else the reason. */
  const std::string &getErrorMessage() const { return error_message_; }

protected:
  std::string getClassName() const override { return "MedialScaffoldReconstruction"; }

  void performReconstruction(pcl::PolygonMesh &output) override;
  void performReconstruction(pcl::PointCloud<PointInT> &points,
                             std::vector<pcl::Vertices> &polygons) override;

private:
  /** \brief Runs the core on input_/indices_; false (and PCL_ERROR) on failure. */
  bool runCore(std::vector<pcl::Vertices> &polygons);

  pcl_ms::Parameters parameters_;
  bool use_sensor_origin_ = true;
  NormalCloud::ConstPtr normals_;
  std::vector<pcl::Vertices> initial_triangles_;
  pcl_ms::Result result_;
  std::string error_message_;

  using SurfaceReconstruction<PointInT>::input_;
  using SurfaceReconstruction<PointInT>::indices_;
  using SurfaceReconstruction<PointInT>::check_tree_;
};

} // namespace pcl

#ifdef PCL_NO_PRECOMPILE
#include <pcl_ms/impl/medial_scaffold_reconstruction.hpp>
#endif
