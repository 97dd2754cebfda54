// SPDX-License-Identifier: GPL-3.0-or-later
// The pipeline (docs/algorithm.md, "Code layout" and section 1). In: the
// user's PointView and Parameters (and initial triangles, if any). Out: a
// Result whose triangles and loops use the user's record numbers. Prepares
// the points, meshes them in one piece or in buckets, finishes the surface.
#include <pcl_ms/buckets.h>
#include <pcl_ms/finish.h>
#include <pcl_ms/medial_axis.h>
#include <pcl_ms/mesh_points.h>
#include <pcl_ms/prepared_points.h>
#include <pcl_ms/reconstruct.h>

#include "far_points.h"
#include "point_keys.h"
#include "populate_pages.h"
#include "sort_unique.h"
#include "threads.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <tuple>

#ifdef __GLIBC__
#include <malloc.h>
#endif

namespace pcl_ms {

std::string Parameters::validate() const {
  std::ostringstream reason;
  if (!(std::isfinite(rho) && rho > 0))
    reason << "rho must be a positive number (got " << rho << ")";
  else if (fill_holes_max_edges < 0 || fill_holes_max_edges == 1 || fill_holes_max_edges == 2)
    reason << "fill_holes must be 0 (off) or a number of edges >= 3 (got " << fill_holes_max_edges
           << ")";
  else if (viewpoint && !(std::isfinite((*viewpoint)[0]) && std::isfinite((*viewpoint)[1]) &&
                          std::isfinite((*viewpoint)[2])))
    reason << "the viewpoint must be finite (got " << (*viewpoint)[0] << ", " << (*viewpoint)[1]
           << ", " << (*viewpoint)[2] << ")";
  else if (!(std::isfinite(normal_weight) && normal_weight >= 0))
    reason << "normal weight must be >= 0 (got " << normal_weight << ")";
  else if (!(close_ranking_tolerance >= 0 && close_ranking_tolerance < 1))
    reason << "close-ranking tolerance must be in [0, 1) (got " << close_ranking_tolerance << ")";
  else if (!(std::isfinite(delay_factor) && delay_factor > 1))
    reason << "delay factor must be > 1 (got " << delay_factor << ")";
  else if (max_delays < 0 || max_delays > 100)
    reason << "max delays must be in [0, 100] (got " << max_delays << ")";
  else if (num_threads < 0)
    reason << "number of threads must be >= 0 (got " << num_threads << ")";
  else if (bucket_points != 0 && bucket_points < min_bucket_points)
    reason << "bucket size must be 0 (automatic) or at least " << min_bucket_points
           << " points (got " << bucket_points << ")";
  else if (!(std::isfinite(time_limit_seconds) && time_limit_seconds >= 0))
    reason << "time limit must be 0 (none) or a number of seconds > 0 (got " << time_limit_seconds
           << ")";
  else if (initial_triangles_mode != InitialTrianglesMode::fixed &&
           initial_triangles_mode != InitialTrianglesMode::preferred)
    reason << "initial triangles mode must be fixed or preferred (got "
           << static_cast<int>(initial_triangles_mode) << ")";
  else if (grid_buckets < 0 || grid_buckets > max_grid_buckets)
    reason << "grid buckets must be in [0, " << max_grid_buckets << "] (got " << grid_buckets
           << ")";
  return reason.str();
}

std::size_t Result::numberOfNonOrientableComponents() const {
  return static_cast<std::size_t>(
      std::count(component_orientable.begin(), component_orientable.end(), false));
}

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The process's peak resident set so far (VmHWM), or 0 where unknown. The
/// kernel syncs per-thread counters lazily, so after worker threads a later
/// reading can be a little lower: callers keep the running maximum.
std::size_t peakResidentBytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.compare(0, 6, "VmHWM:") == 0)
      return static_cast<std::size_t>(std::strtoull(line.c_str() + 6, nullptr, 10)) * 1024;
  return 0;
}

/// Hands the heap's free pages back to the system. The bucket threads'
/// small allocations leave them scattered through each thread's heap, where
/// they stayed resident through the finishing and the caller's conversion
/// of the result: at 10M points, handing them back lowered the peak by
/// about 0.5 GB (docs/algorithm.md, section 4, "Memory").
void returnFreeHeapPages() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

} // namespace

std::string tooFewPoints(const PreparationCounts &counts, std::size_t distinct) {
  std::ostringstream reason;
  reason << "need at least 3 distinct valid points, got " << distinct << " (" << counts.input_points
         << " given, " << counts.invalid_points << " NaN/Inf, " << counts.duplicate_points
         << " duplicates, " << counts.far_points << " far stray points)";
  return reason.str();
}

/// Prepares the distinct, finite points in Morton (Z-curve) order. Every
/// later stage walks the points' neighbourhoods: with neighbours at nearby
/// indices their arrays stay in cache, which saves about a fifth of the time
/// on unorganised clouds. One sort by (Morton code, coordinates, record)
/// both orders the points and puts exact duplicates next to each other, the
/// earliest record first. The order depends on the coordinates only, so the
/// same input gives the same mesh.
PreparedPoints preparePoints(const PointView &view, bool with_normals, bool map_records,
                             Result &result) {
  const std::size_t count = view.indices ? view.indices.size() : view.size;
  result.input_points = count;
  if (count > 0 && !view.xyz)
    throw ReconstructionError("the point array is null");
  if (view.size >= std::numeric_limits<VertexIndex>::max())
    throw ReconstructionError("too many points for 32-bit indices");

  std::vector<VertexIndex> records;
  records.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    std::size_t record = i;
    if (view.indices) {
      const std::int64_t index = view.indices[i];
      if (index < 0 || static_cast<std::size_t>(index) >= view.size)
        throw ReconstructionError("index " + std::to_string(index) + " is outside the cloud of " +
                                  std::to_string(view.size) + " points");
      record = static_cast<std::size_t>(index);
    }
    const float *p = detail::recordAt(view.xyz, view.stride, record);
    if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))
      records.push_back(static_cast<VertexIndex>(record));
    else
      ++result.invalid_points;
  }

  // Far stray points stay out of the surface, and out of the bounding box
  // and centre, so that the rest of the cloud is meshed as without them.
  detail::FarPoints far;
  {
    std::vector<Eigen::Vector3f> finite;
    detail::resizeForWriting(finite, records.size());
    for (std::size_t i = 0; i < records.size(); ++i)
      finite[i] = Eigen::Vector3f(detail::recordAt(view.xyz, view.stride, records[i]));
    far = detail::findFarPoints(finite);
  }
  result.far_points = far.count;
  if (far.count > 0) {
    std::size_t kept = 0;
    for (std::size_t i = 0; i < records.size(); ++i)
      if (!far.is_far[i])
        records[kept++] = records[i];
    records.resize(kept);
  }
  std::vector<detail::PointKey> keys;
  detail::resizeForWriting(keys, records.size());
  {
    const detail::MortonCells cells(far.low, far.high);
    constexpr std::size_t grain = 1 << 14;
    detail::parallelFor(tbb::blocked_range<std::size_t>(0, records.size(), grain),
                        [&](const tbb::blocked_range<std::size_t> &part) {
                          for (std::size_t i = part.begin(); i != part.end(); ++i)
                            keys[i] = cells.key(detail::recordAt(view.xyz, view.stride, records[i]),
                                                records[i]);
                        });
  }
  records.clear();
  records.shrink_to_fit();
  detail::parallelSort(keys.begin(), keys.end(), std::less<>()); // keys are distinct: one order

  PreparedPoints prepared;
  if (map_records) {
    prepared.prepared_of_record.reserve(view.size);
    detail::populateCapacity(prepared.prepared_of_record);
    prepared.prepared_of_record.assign(view.size, not_prepared);
  }
  const Eigen::Vector3d &centre = far.median;
  prepared.centre = centre;
  prepared.positions.reserve(keys.size());
  prepared.user_index.reserve(keys.size());
  detail::populateCapacity(prepared.positions);
  detail::populateCapacity(prepared.user_index);
  if (with_normals)
    prepared.normals.reserve(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const detail::PointKey &key = keys[i];
    if (i > 0 && key.coordinates == keys[i - 1].coordinates) {
      // An exact duplicate of the record kept just before.
      ++result.duplicate_points;
      if (map_records)
        prepared.prepared_of_record[key.record] =
            static_cast<VertexIndex>(prepared.positions.size() - 1);
      continue;
    }
    if (map_records)
      prepared.prepared_of_record[key.record] = static_cast<VertexIndex>(prepared.positions.size());
    // Centred: circumcentres of far-off points lose precision otherwise.
    prepared.positions.push_back(
        Eigen::Vector3d(key.coordinates[0], key.coordinates[1], key.coordinates[2]) - centre);
    prepared.user_index.push_back(key.record);
    if (with_normals) {
      prepared.normals.push_back(
          detail::unitNormalOrZero(detail::recordAt(view.normals, view.normal_stride, key.record)));
    }
  }
  result.used_points = prepared.positions.size();
  if (prepared.positions.size() < 3)
    throw ReconstructionError(
        tooFewPoints({count, result.invalid_points, result.duplicate_points, result.far_points},
                     prepared.positions.size()));
  return prepared;
}

namespace {

/// Preferred initial triangles in distinct-point indices, corners
/// ascending, each once (docs/algorithm.md, "Initial triangles"): the
/// repeated ones are merged and those that use an invalid or missing point,
/// or one point twice, are left out, counted in `result`.
std::vector<Triangle> preparePreferredTriangles(const std::vector<Triangle> &initial,
                                                const PreparedPoints &prepared, Result &result) {
  std::vector<Triangle> mapped;
  mapped.reserve(initial.size());
  for (const Triangle &corners : initial) {
    Triangle triangle;
    bool valid = true;
    for (int k = 0; k < 3; ++k) {
      const VertexIndex record = corners[k];
      triangle[k] = record < prepared.prepared_of_record.size()
                        ? prepared.prepared_of_record[record]
                        : not_prepared;
      valid = valid && triangle[k] != not_prepared;
    }
    std::sort(triangle.begin(), triangle.end());
    if (!valid || triangle[0] == triangle[1] || triangle[1] == triangle[2]) {
      ++result.initial_invalid;
      continue;
    }
    mapped.push_back(triangle);
  }
  std::sort(mapped.begin(), mapped.end());
  const auto end = std::unique(mapped.begin(), mapped.end());
  result.initial_duplicates = static_cast<std::size_t>(mapped.end() - end);
  mapped.erase(end, mapped.end());
  return mapped;
}

/// How many of the distinct initial triangles (distinct-point indices) the
/// mesh (distinct-point indices) contains.
std::size_t countKept(std::vector<Triangle> initial, const std::vector<Triangle> &mesh) {
  for (Triangle &triangle : initial)
    std::sort(triangle.begin(), triangle.end());
  detail::sortUnique(initial);
  std::size_t kept = 0;
  for (Triangle triangle : mesh) {
    std::sort(triangle.begin(), triangle.end());
    kept += std::binary_search(initial.begin(), initial.end(), triangle);
  }
  return kept;
}

/// The user's initial triangles in distinct-point indices. Each must use
/// three distinct input points, appear once, and share each edge with at
/// most one other: the greedy builds a 2-manifold around them.
std::vector<Triangle> prepareInitialTriangles(const std::vector<Triangle> &initial,
                                              const PreparedPoints &prepared) {
  std::vector<Triangle> mapped;
  mapped.reserve(initial.size());
  for (std::size_t t = 0; t < initial.size(); ++t) {
    Triangle triangle;
    for (int k = 0; k < 3; ++k) {
      const VertexIndex record = initial[t][k];
      const VertexIndex v = record < prepared.prepared_of_record.size()
                                ? prepared.prepared_of_record[record]
                                : not_prepared;
      if (v == not_prepared)
        throw ReconstructionError("initial triangle " + std::to_string(t) + " uses point " +
                                  std::to_string(record) +
                                  ", which is not a valid point of the input");
      triangle[k] = v;
    }
    std::sort(triangle.begin(), triangle.end());
    if (triangle[0] == triangle[1] || triangle[1] == triangle[2])
      throw ReconstructionError("initial triangle " + std::to_string(t) +
                                " has two corners at the same position");
    mapped.push_back(triangle);
  }
  std::vector<Triangle> sorted = mapped;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
    throw ReconstructionError("the initial triangles contain the same triangle twice");
  std::vector<std::pair<VertexIndex, VertexIndex>> edges;
  for (const Triangle &triangle : sorted) {
    edges.emplace_back(triangle[0], triangle[1]);
    edges.emplace_back(triangle[1], triangle[2]);
    edges.emplace_back(triangle[0], triangle[2]);
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 2; i < edges.size(); ++i)
    if (edges[i] == edges[i - 2])
      throw ReconstructionError("the initial triangles share an edge among more than two");
  return mapped;
}

Result reconstructShared(const PointView &points, const Parameters &parameters,
                         const std::vector<Triangle> &initial_triangles, BucketExchange &exchange);

Result meshPrepared(const PreparedPoints &prepared, const std::vector<Triangle> &initial_triangles,
                    const Parameters &parameters, BucketExchange &exchange,
                    const Deadline &deadline, Clock::time_point start, Result result);

/// The medial axis of the finished surface, into `result` (Parameters::compute_medial_axis).
void addMedialAxis(const PreparedPoints &prepared, const std::vector<Triangle> &triangles,
                   const Deadline &deadline, Result &result);
/// The finished surface into `result`, in the user's records.
void takeFinishedSurface(FinishedSurface &&surface, const PreparedPoints &prepared, Result &result);
/// The finished surface, whose numbers are the user's records, into `result`.
void moveFinishedSurface(FinishedSurface &&surface, Result &result);
/// The checks every entry point makes before any work.
void checkParameters(const Parameters &parameters, bool has_normals) {
  const std::string invalid = parameters.validate();
  if (!invalid.empty())
    throw ReconstructionError(invalid);
  if (parameters.use_normals && !has_normals)
    throw ReconstructionError("normals were requested but none were given");
}

/// Parameters::num_threads, or one thread for a small cloud meshed in one
/// piece (Parameters::min_points_for_threads); `points` counts the cloud's
/// points.
int threadsWorthStarting(const Parameters &parameters, std::size_t points) {
  if (points < parameters.min_points_for_threads && !usesBuckets(points, parameters))
    return 1;
  return parameters.num_threads;
}

} // namespace

Result reconstruct(const PointView &points, const Parameters &parameters) {
  return reconstruct(points, parameters, {});
}

Result reconstruct(const PointView &points, const Parameters &parameters,
                   BucketExchange &exchange) {
  return reconstructShared(points, parameters, {}, exchange);
}

Result reconstruct(const PointView &points, const Parameters &parameters,
                   const std::vector<Triangle> &initial_triangles) {
  BucketExchange one_process;
  return reconstructShared(points, parameters, initial_triangles, one_process);
}

Result reconstructSlices(PreparedSlice &&slice, const Parameters &parameters, ProcessGroup &group,
                         FinishedRun *runs) {
  const Clock::time_point start = Clock::now();
  if (runs)
    *runs = FinishedRun(); // unused unless bucketed
  checkParameters(parameters, true);
  std::vector<double> missing_normals{
      parameters.use_normals && slice.points.normals.size() != slice.points.positions.size() ? 1.0
                                                                                             : 0.0};
  group.maximum(missing_normals);
  if (missing_normals[0] > 0)
    throw ReconstructionError("normals were requested but the points were prepared without");
  const Deadline deadline(parameters.time_limit_seconds);
  Result result;
  result.input_points = slice.counts.input_points;
  result.invalid_points = slice.counts.invalid_points;
  result.duplicate_points = slice.counts.duplicate_points;
  result.far_points = slice.counts.far_points;
  result.used_points = slice.total;
  BucketExchange one_process;
  if (parameters.allow_non_manifold || !usesBuckets(slice.total, parameters)) {
    // One piece: process 0 meshes it alone, as reconstruct() would.
    const PreparedPoints joined =
        joinSlicesAtProcessZero(slice.points, parameters.use_normals, group);
    slice = PreparedSlice();
    if (group.process() != 0)
      return result;
    result.peak_memory.prepare = peakResidentBytes();
    return meshPrepared(joined, {}, parameters, one_process, deadline, start, std::move(result));
  }
  result.peak_memory.prepare = peakResidentBytes();
  SharedSurface shared = meshSlicesInBuckets(slice, parameters, &deadline, group, runs != nullptr);
  slice = PreparedSlice();
  returnFreeHeapPages();
  result.d_med = shared.surface.d_med;
  result.d_max = parameters.rho * shared.surface.d_med;
  result.bucket_statistics = shared.surface.statistics;
  result.timings.delaunay = shared.surface.delaunay_seconds;
  result.timings.scaffold = shared.surface.scaffold_seconds;
  result.timings.greedy = shared.surface.greedy_seconds;
  result.timings.finish = shared.finish_seconds;
  result.peak_memory.scaffold = result.peak_memory.greedy = result.peak_memory.finish =
      std::max(result.peak_memory.prepare, peakResidentBytes());
  if (shared.run.used) {
    *runs = std::move(shared.run);
    if (group.process() == 0)
      moveFinishedSurface(std::move(shared.finished), result); // in the user's records
  } else if (group.process() == 0) {
    if (parameters.compute_medial_axis)
      addMedialAxis(shared.points, shared.finished.triangles, deadline, result);
    takeFinishedSurface(std::move(shared.finished), shared.points, result);
  }
  result.timings.total = secondsSince(start);
  return result;
}

namespace {

Result reconstructShared(const PointView &points, const Parameters &parameters,
                         const std::vector<Triangle> &initial_triangles, BucketExchange &exchange) {
  const Clock::time_point start = Clock::now();
  checkParameters(parameters, points.normals != nullptr);

  const Deadline deadline(parameters.time_limit_seconds);
  Result result;
  Clock::time_point stage = Clock::now();
  const std::size_t selected = points.indices ? points.indices.size() : points.size;
  const int preparing_threads = threadsWorthStarting(parameters, selected);
  const PreparedPoints prepared = detail::withThreads(preparing_threads, [&] {
    return preparePoints(points, parameters.use_normals, !initial_triangles.empty(), result);
  });
  result.timings.prepare = secondsSince(stage);
  result.peak_memory.prepare = peakResidentBytes();
  exchange.pointsPrepared(); // `points` is not read below
  return meshPrepared(prepared, initial_triangles, parameters, exchange, deadline, start,
                      std::move(result));
}

/// Stages 2 to 4 on prepared points, into `result` (which has the
/// preparation's figures).
Result meshPrepared(const PreparedPoints &prepared, const std::vector<Triangle> &initial_triangles,
                    const Parameters &requested, BucketExchange &exchange, const Deadline &deadline,
                    Clock::time_point start, Result result) {
  Parameters parameters = requested;
  parameters.num_threads = threadsWorthStarting(requested, prepared.positions.size());
  Clock::time_point stage;
  const bool preferred_mode = parameters.initial_triangles_mode == InitialTrianglesMode::preferred;
  const std::vector<Triangle> fixed = preferred_mode
                                          ? std::vector<Triangle>()
                                          : prepareInitialTriangles(initial_triangles, prepared);
  const std::vector<Triangle> preferred =
      preferred_mode ? preparePreferredTriangles(initial_triangles, prepared, result)
                     : std::vector<Triangle>();
  const std::vector<Eigen::Vector3f> *normals =
      parameters.use_normals ? &prepared.normals : nullptr;

  std::vector<Triangle> triangles;
  std::vector<Triangle> seam_triangles;   // Parameters::allow_non_manifold
  std::vector<Triangle> greedy_triangles; // what the finish starts from, with seams
  std::vector<float> local_scale;         // per distinct point
  // Initial triangles and seams are honoured by the one-piece path only.
  const bool in_buckets = initial_triangles.empty() && !parameters.allow_non_manifold &&
                          usesBuckets(prepared.positions.size(), parameters);
  // Only process 0 meshes a one-piece cloud and finishes the surface.
  const bool gathers = exchange.process() == 0;
  if (!in_buckets && !gathers)
    return result;
  if (in_buckets) {
    deadline.check("the preparation");
    BucketedSurface bucketed =
        meshInBuckets(prepared.positions, normals, parameters, &deadline, &exchange);
    returnFreeHeapPages();
    triangles = std::move(bucketed.triangles);
    local_scale = std::move(bucketed.local_scale);
    result.d_med = bucketed.d_med;
    result.d_max = parameters.rho * bucketed.d_med;
    result.bucket_statistics = bucketed.statistics;
    result.timings.delaunay = bucketed.delaunay_seconds;
    result.timings.scaffold = bucketed.scaffold_seconds;
    result.timings.greedy = bucketed.greedy_seconds;
    result.peak_memory.scaffold = result.peak_memory.greedy =
        std::max(result.peak_memory.prepare, peakResidentBytes());
    if (!gathers) {
      result.timings.total = secondsSince(start);
      return result;
    }
  } else {
    ScaffoldOptions options;
    options.rho = parameters.rho;
    options.num_threads = parameters.num_threads;
    options.normals = normals;
    options.normal_weight = parameters.normal_weight;
    options.fixed_triangles = fixed.empty() ? nullptr : &fixed;
    options.preferred_triangles = preferred.empty() ? nullptr : &preferred;
    deadline.check("the preparation");
    MeshedPoints meshed = meshPoints(prepared.positions, options, parameters, &deadline, true,
                                     [&](const MedialScaffold &scaffold) {
                                       deadline.check("the scaffold");
                                       result.planar = scaffold.planar;
                                       result.d_med = scaffold.d_med;
                                       result.d_max = scaffold.d_max;
                                       result.candidates_type1 = scaffold.type1;
                                       result.candidates_type2 = scaffold.type2;
                                       result.candidates_type3 = scaffold.type3;
                                       result.candidates_oversize = scaffold.oversize;
                                       result.candidates_degenerate = scaffold.degenerate;
                                       result.initial_oversize = scaffold.preferred_oversize;
                                       result.initial_invalid += scaffold.preferred_degenerate;
                                       result.peak_memory.scaffold = std::max(
                                           result.peak_memory.prepare, peakResidentBytes());
                                     });
    result.timings.delaunay = meshed.delaunay_seconds;
    result.timings.scaffold = meshed.scaffold_seconds;
    triangles = std::move(meshed.triangles);
    seam_triangles = std::move(meshed.seam_triangles);
    if (!seam_triangles.empty())
      greedy_triangles = triangles;
    local_scale = std::move(meshed.local_scale);
    result.pass1 = meshed.greedy.pass1;
    result.pass2 = meshed.greedy.pass2;
    result.cleanup_undone = meshed.greedy.cleanup_undone;
    result.swapped_pairs = meshed.greedy.swapped_pairs;
    result.timings.greedy = meshed.greedy_seconds;
    result.peak_memory.greedy = std::max(result.peak_memory.scaffold, peakResidentBytes());
  }

  deadline.check("the greedy passes");
  stage = Clock::now();
  std::optional<Eigen::Vector3d> viewpoint;
  if (parameters.viewpoint)
    viewpoint = Eigen::Vector3d((*parameters.viewpoint)[0], (*parameters.viewpoint)[1],
                                (*parameters.viewpoint)[2]) -
                prepared.centre;
  // The user's fixed triangles must survive the twist repair. Preferred ones
  // are not protected: anchoring their corners kept 3 more of them on the
  // bunny soup of tests/test_soup.cpp and left 5 more loops open; sparing
  // just them kept 14 more on CGAL's cow soup but left the cow one-sided.
  // The finish stage's parallel loops use the threads the user allowed.
  FinishedSurface surface;
  detail::withThreads(parameters.num_threads, [&] {
    surface =
        finishSurface(std::move(triangles), prepared.positions, parameters.fill_holes_max_edges,
                      SideLimit{&local_scale, parameters.rho}, fixed.empty() ? nullptr : &fixed,
                      viewpoint ? &*viewpoint : nullptr);
  });
  std::vector<std::array<VertexIndex, 2>> seam_edges;
  if (!seam_triangles.empty()) {
    const std::size_t before = surface.triangles.size();
    seam_edges = attachSeamTriangles(surface, seam_triangles, greedy_triangles);
    result.seam_triangles = surface.triangles.size() - before;
  }
  deadline.check("the finish");
  if (!fixed.empty() || !preferred.empty())
    result.initial_kept = countKept(fixed.empty() ? preferred : fixed, surface.triangles);
  result.timings.finish = secondsSince(stage);
  result.peak_memory.finish = std::max(result.peak_memory.greedy, peakResidentBytes());
  if (parameters.compute_medial_axis)
    addMedialAxis(prepared, surface.triangles, deadline, result);
  for (auto &edge : seam_edges) {
    edge = {prepared.user_index[edge[0]], prepared.user_index[edge[1]]};
    if (edge[0] > edge[1])
      std::swap(edge[0], edge[1]);
  }
  std::sort(seam_edges.begin(), seam_edges.end());
  result.seam_edges = std::move(seam_edges);
  takeFinishedSurface(std::move(surface), prepared, result);
  result.timings.total = secondsSince(start);
  return result;
}

void addMedialAxis(const PreparedPoints &prepared, const std::vector<Triangle> &triangles,
                   const Deadline &deadline, Result &result) {
  // Read off a Delaunay triangulation of all prepared points (buckets
  // never had one of the whole cloud); nothing of this runs when off.
  const Clock::time_point stage = Clock::now();
  MedialAxis axis = computeMedialAxis(prepared.positions, triangles);
  for (Eigen::Vector3d &position : axis.node_positions)
    position += prepared.centre;
  result.medial_axis = std::move(axis);
  result.timings.medial_axis = secondsSince(stage);
  deadline.check("the medial axis");
}

void takeFinishedSurface(FinishedSurface &&surface, const PreparedPoints &prepared,
                         Result &result) {
  for (Triangle &triangle : surface.triangles)
    for (VertexIndex &v : triangle)
      v = prepared.user_index[v];
  for (auto &loop : surface.boundary_loops)
    for (VertexIndex &v : loop)
      v = prepared.user_index[v];
  moveFinishedSurface(std::move(surface), result);
}

void moveFinishedSurface(FinishedSurface &&surface, Result &result) {
  result.triangles = std::move(surface.triangles);
  result.boundary_loops = std::move(surface.boundary_loops);
  result.triangle_component = std::move(surface.triangle_component);
  result.component_orientable = std::move(surface.component_orientable);
  result.holes_filled = surface.holes_filled;
  result.twist_triangles_removed = surface.twist_triangles_removed;
}

} // namespace

} // namespace pcl_ms
