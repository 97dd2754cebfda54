// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh-quality metrics, second half: a mesh against a reference surface
// (compareWithReference). In: the mesh and the reference, vertices and index
// triples. Out: a ReferenceReport (sampled distances both ways through CGAL
// AABB trees, precision, recall, F-score, triangles shared exactly).
#include <pcl_ms/mesh_quality.h>

#include "mesh_triangles.h"
#include "morton.h"
#include "position_keys.h"

#include <CGAL/AABB_segment_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <Eigen/Geometry>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <tuple>
#include <unordered_map>
#include <utility>

namespace pcl_ms {
namespace {

using namespace metrics_detail;

// Plain doubles are enough (and faster) for the distance constructions.
using DistanceKernel = CGAL::Simple_cartesian<double>;
using Point3 = DistanceKernel::Point_3;
using Triangle3 = DistanceKernel::Triangle_3;
using Segment3 = DistanceKernel::Segment_3;
using TrianglePrimitive =
    CGAL::AABB_triangle_primitive<DistanceKernel, std::vector<Triangle3>::const_iterator>;
using SegmentPrimitive =
    CGAL::AABB_segment_primitive<DistanceKernel, std::vector<Segment3>::const_iterator>;
using TriangleTree = CGAL::AABB_tree<CGAL::AABB_traits<DistanceKernel, TrianglePrimitive>>;
using SegmentTree = CGAL::AABB_tree<CGAL::AABB_traits<DistanceKernel, SegmentPrimitive>>;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------
// Comparison with a reference

/// Doubles in [0, 1) from 53 random bits. Written out rather than using
/// std::uniform_real_distribution, whose output differs between standard
/// libraries, so that samples are the same on every platform.
double unitDouble(std::mt19937 &engine) {
  const std::uint64_t high = engine() >> 5; // 27 bits
  const std::uint64_t low = engine() >> 6;  // 26 bits
  return static_cast<double>((high << 26) | low) * 0x1.0p-53;
}

Point3 toPoint(const Eigen::Vector3d &vector) { return {vector.x(), vector.y(), vector.z()}; }

/// Triangles usable for distances: indices in range and finite corners.
std::vector<Triangle> usableTriangles(const std::vector<Eigen::Vector3d> &vertices,
                                      const std::vector<Triangle> &triangles) {
  std::vector<Triangle> usable;
  usable.reserve(triangles.size());
  for (const Triangle &triangle : triangles)
    if (indicesInRange(triangle, vertices.size()) && isFinite(vertices[triangle[0]]) &&
        isFinite(vertices[triangle[1]]) && isFinite(vertices[triangle[2]]))
      usable.push_back(triangle);
  return usable;
}

constexpr VertexIndex kUnmatched = std::numeric_limits<VertexIndex>::max();

/// One id per distinct position over both meshes, reference first: ids below
/// referenceCount() are positions of reference vertices. Coincidence of
/// vertices and triangles between the meshes then is integer comparison.
class PositionIds {
public:
  explicit PositionIds(PositionPrecision precision) : precision_(precision) {}
  /// Id per vertex used by a usable triangle, kUnmatched for the others.
  std::vector<VertexIndex> assign(const std::vector<Eigen::Vector3d> &vertices,
                                  const std::vector<Triangle> &usable) {
    std::vector<VertexIndex> ids(vertices.size(), kUnmatched);
    for (const Triangle &triangle : usable)
      for (VertexIndex vertex : triangle)
        if (ids[vertex] == kUnmatched)
          ids[vertex] = ids_.emplace(positionKey(vertices[vertex], precision_),
                                     static_cast<VertexIndex>(ids_.size()))
                            .first->second;
    return ids;
  }
  void closeReference() { reference_count_ = ids_.size(); }
  std::size_t referenceCount() const { return reference_count_; }
  std::size_t size() const { return ids_.size(); }

private:
  PositionPrecision precision_;
  std::unordered_map<PositionKey, VertexIndex, PositionKeyHash> ids_;
  std::size_t reference_count_ = 0;
};

/// Nearest reference position within a tolerance: a hash grid with the
/// tolerance as cell size, so candidates lie in the 27 cells around a point.
class ToleranceMatcher {
public:
  ToleranceMatcher(const std::vector<Eigen::Vector3d> &reference_vertices,
                   const std::vector<VertexIndex> &reference_ids, std::size_t id_count,
                   double tolerance)
      : tolerance_(tolerance), positions_(id_count) {
    std::vector<char> stored(id_count, 0);
    for (std::size_t vertex = 0; vertex < reference_vertices.size(); ++vertex) {
      const VertexIndex id = reference_ids[vertex];
      if (id == kUnmatched || stored[id])
        continue; // unused, or a repeat of a position already stored
      stored[id] = 1;
      positions_[id] = reference_vertices[vertex];
      grid_[cellKey(cellOf(reference_vertices[vertex]))].push_back(id);
    }
  }

  VertexIndex match(const Eigen::Vector3d &point) const {
    const std::array<std::int64_t, 3> centre = cellOf(point);
    VertexIndex best = kUnmatched;
    double best_squared = tolerance_ * tolerance_;
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = grid_.find(cellKey({centre[0] + dx, centre[1] + dy, centre[2] + dz}));
          if (it == grid_.end())
            continue;
          for (VertexIndex candidate : it->second) {
            const double squared = (positions_[candidate] - point).squaredNorm();
            // Ties go to the smaller id, so the result does not depend on
            // the order in which cells are visited.
            if (squared < best_squared || (squared == best_squared && candidate < best)) {
              best_squared = squared;
              best = candidate;
            }
          }
        }
    return best;
  }

private:
  std::array<std::int64_t, 3> cellOf(const Eigen::Vector3d &point) const {
    // Clamped so that far-away points cannot overflow the conversion; they
    // only ever share a cell with equally far-away ones.
    constexpr double kLimit = 0x1.0p60;
    std::array<std::int64_t, 3> cell{};
    for (int axis = 0; axis < 3; ++axis)
      cell[static_cast<std::size_t>(axis)] = static_cast<std::int64_t>(
          std::clamp(std::floor(point[axis] / tolerance_), -kLimit, kLimit));
    return cell;
  }

  // Two cells hashing alike only add candidates that the distance test then
  // rejects, so a 64-bit hash of the cell is a safe key.
  static std::uint64_t cellKey(const std::array<std::int64_t, 3> &cell) {
    return mixBits(static_cast<std::uint64_t>(cell[0]) ^
                   mixBits(static_cast<std::uint64_t>(cell[1]) ^
                           mixBits(static_cast<std::uint64_t>(cell[2]))));
  }

  double tolerance_;
  std::vector<Eigen::Vector3d> positions_;
  std::unordered_map<std::uint64_t, std::vector<VertexIndex>> grid_;
};

Triangle keyOf(const Triangle &triangle, const std::vector<VertexIndex> &ids) {
  return sortedCorners({ids[triangle[0]], ids[triangle[1]], ids[triangle[2]]});
}

bool isMatched(const Triangle &key) {
  return key[0] != kUnmatched && key[1] != kUnmatched && key[2] != kUnmatched;
}

/// For each key, whether it occurs in `others` (which gets sorted).
std::vector<char> occursIn(const std::vector<Triangle> &keys, std::vector<Triangle> others) {
  std::sort(others.begin(), others.end());
  std::vector<char> found(keys.size(), 0);
  for (std::size_t i = 0; i < keys.size(); ++i)
    found[i] = isMatched(keys[i]) && std::binary_search(others.begin(), others.end(), keys[i]);
  return found;
}

/// Points on a mesh where distances are measured, with a flag for those
/// known to lie exactly on the other mesh (see Surface::sample).
struct SampleSet {
  std::vector<Point3> points;
  std::vector<char> on_other;
  std::size_t deterministic_count = 0; // the random samples follow these
};

/// A mesh surface prepared for closest-point queries and for sampling.
/// Degenerate triangles are kept as their longest edge in a segment tree:
/// they are part of the surface as a set, and CGAL's point-triangle
/// projection is not reliable for them.
class Surface {
public:
  Surface(const std::vector<Eigen::Vector3d> &vertices, const std::vector<Triangle> &usable)
      : vertices_(vertices), usable_(usable) {
    for (std::size_t t = 0; t < usable.size(); ++t) {
      const Triangle &triangle = usable[t];
      const Eigen::Vector3d &a = vertices[triangle[0]];
      const Eigen::Vector3d &b = vertices[triangle[1]];
      const Eigen::Vector3d &c = vertices[triangle[2]];
      if (!isDegenerate(vertices, triangle)) {
        proper_.emplace_back(toPoint(a), toPoint(b), toPoint(c));
        proper_source_.push_back(t);
        continue;
      }
      const double ab = (b - a).squaredNorm(), bc = (c - b).squaredNorm(),
                   ca = (a - c).squaredNorm();
      if (ab >= bc && ab >= ca)
        collapsed_.emplace_back(toPoint(a), toPoint(b));
      else if (bc >= ca)
        collapsed_.emplace_back(toPoint(b), toPoint(c));
      else
        collapsed_.emplace_back(toPoint(c), toPoint(a));
    }
  }
  Surface(const Surface &) = delete;
  Surface &operator=(const Surface &) = delete;

  bool empty() const { return usable_.empty(); }

  /// Deterministic samples (every referenced vertex, every centroid, every
  /// edge midpoint, so that no triangle, however thin, can fall between the
  /// random samples), then `count` area-uniform random ones. A sample is
  /// flagged as on the other mesh when it comes from a vertex or triangle
  /// that the other mesh has at exactly the same coordinates: its distance
  /// is exactly 0 and needs no query.
  SampleSet sample(const std::vector<char> &vertex_on_other,
                   const std::vector<char> &triangle_on_other, std::size_t count,
                   std::uint32_t seed, std::uint32_t stream) const {
    SampleSet samples;
    std::vector<VertexIndex> used;
    // Edge keys, each with whether its triangle lies on the other mesh.
    std::vector<std::pair<std::uint64_t, bool>> edges;
    used.reserve(3 * usable_.size());
    edges.reserve(3 * usable_.size());
    for (std::size_t t = 0; t < usable_.size(); ++t)
      for (std::size_t i = 0; i < 3; ++i) {
        const VertexIndex from = usable_[t][i], to = usable_[t][(i + 1) % 3];
        used.push_back(from);
        if (from != to)
          edges.emplace_back(edgeKey(from, to), triangle_on_other[t] != 0);
      }
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    // Sorting puts an edge's "on the other mesh" copies last, where the
    // loop below reads them.
    std::sort(edges.begin(), edges.end());

    const std::size_t expected = used.size() + usable_.size() + edges.size() + count;
    samples.points.reserve(expected);
    samples.on_other.reserve(expected);
    for (VertexIndex vertex : used) {
      samples.points.push_back(toPoint(vertices_[vertex]));
      samples.on_other.push_back(vertex_on_other[vertex]);
    }
    for (std::size_t t = 0; t < usable_.size(); ++t) {
      const Triangle &triangle = usable_[t];
      samples.points.push_back(toPoint(
          (vertices_[triangle[0]] + vertices_[triangle[1]] + vertices_[triangle[2]]) / 3.0));
      samples.on_other.push_back(triangle_on_other[t]);
    }
    for (std::size_t k = 0; k < edges.size(); ++k) {
      if (k + 1 < edges.size() && edges[k + 1].first == edges[k].first)
        continue;
      const std::uint64_t key = edges[k].first;
      samples.points.push_back(
          toPoint(0.5 * (vertices_[key >> 32] + vertices_[key & 0xffffffffu])));
      samples.on_other.push_back(edges[k].second);
    }
    samples.deterministic_count = samples.points.size();
    appendRandomSamples(triangle_on_other, count, seed, stream, samples);
    return samples;
  }

  /// Distance from every sample to this surface. Queries go in Morton order
  /// in fixed blocks, each query using the previous closest point as its
  /// hint; blocks are spread over threads. Blocks do not depend on the
  /// thread count, so neither do the results.
  std::vector<double> distances(const SampleSet &samples) {
    std::vector<double> result(samples.points.size(), 0.0);
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < samples.points.size(); ++i)
      if (!samples.on_other[i])
        order.push_back(i);
    if (order.empty())
      return result; // a mesh compared with itself needs no tree at all
    buildTrees();
    sortAlongMortonCurve(samples.points, order);

    constexpr std::size_t kBlock = 256;
    const std::size_t block_count = (order.size() + kBlock - 1) / kBlock;
    // TBB, like the reconstruction: the caller's task arena (and its thread
    // limit) applies. Each block has its own hints and writes its own
    // entries, so the result does not depend on the scheduling.
    tbb::parallel_for(std::size_t{0}, block_count, [&](std::size_t block) {
      Hints hints;
      const std::size_t end = std::min(order.size(), (block + 1) * kBlock);
      for (std::size_t k = block * kBlock; k < end; ++k)
        result[order[k]] = std::sqrt(squaredDistance(samples.points[order[k]], hints));
    });
    return result;
  }

private:
  struct Hints {
    std::optional<Point3> triangle, segment;
  };

  /// Trees and their search hints are built before any query: queries then
  /// only read them, which lets several threads share them.
  void buildTrees() {
    if (!proper_.empty() && triangle_tree_.empty()) {
      triangle_tree_.insert(proper_.begin(), proper_.end());
      triangle_tree_.build();
      triangle_tree_.accelerate_distance_queries();
    }
    if (!collapsed_.empty() && segment_tree_.empty()) {
      segment_tree_.insert(collapsed_.begin(), collapsed_.end());
      segment_tree_.build();
      segment_tree_.accelerate_distance_queries();
    }
  }

  double squaredDistance(const Point3 &query, Hints &hints) const {
    double best = kInfinity;
    if (!proper_.empty()) {
      hints.triangle = hints.triangle ? triangle_tree_.closest_point(query, *hints.triangle)
                                      : triangle_tree_.closest_point(query);
      best = CGAL::squared_distance(query, *hints.triangle);
    }
    if (!collapsed_.empty()) {
      hints.segment = hints.segment ? segment_tree_.closest_point(query, *hints.segment)
                                    : segment_tree_.closest_point(query);
      best = std::min(best, CGAL::squared_distance(query, *hints.segment));
    }
    return best;
  }

  static void sortAlongMortonCurve(const std::vector<Point3> &points,
                                   std::vector<std::size_t> &order) {
    if (order.empty())
      return;
    Eigen::Vector3d low = Eigen::Vector3d::Constant(kInfinity), high = -low;
    for (std::size_t index : order) {
      const Eigen::Vector3d point(points[index].x(), points[index].y(), points[index].z());
      low = low.cwiseMin(point);
      high = high.cwiseMax(point);
    }
    const double extent = std::max((high - low).maxCoeff(), std::numeric_limits<double>::min());
    const double cells = static_cast<double>((1 << 21) - 1);
    std::vector<std::pair<std::uint64_t, std::size_t>> coded;
    coded.reserve(order.size());
    for (std::size_t index : order) {
      std::uint32_t cell[3];
      for (int axis = 0; axis < 3; ++axis) {
        const double scaled = (points[index][axis] - low[axis]) / extent * cells;
        cell[axis] = static_cast<std::uint32_t>(std::clamp(scaled, 0.0, cells));
      }
      coded.emplace_back(detail::mortonCode(cell[0], cell[1], cell[2]), index);
    }
    std::sort(coded.begin(), coded.end());
    for (std::size_t k = 0; k < coded.size(); ++k)
      order[k] = coded[k].second;
  }

  void appendRandomSamples(const std::vector<char> &triangle_on_other, std::size_t count,
                           std::uint32_t seed, std::uint32_t stream, SampleSet &samples) const {
    std::vector<double> cumulative_area;
    cumulative_area.reserve(proper_.size());
    double total = 0;
    for (const Triangle3 &triangle : proper_) {
      total += std::sqrt(triangle.squared_area());
      cumulative_area.push_back(total);
    }
    if (count == 0 || !(total > 0))
      return;
    std::seed_seq seeds{seed, stream};
    std::mt19937 engine(seeds);
    for (std::size_t n = 0; n < count; ++n) {
      const double target = unitDouble(engine) * total;
      const std::size_t index = std::min<std::size_t>(
          static_cast<std::size_t>(
              std::upper_bound(cumulative_area.begin(), cumulative_area.end(), target) -
              cumulative_area.begin()),
          proper_.size() - 1);
      // sqrt makes the density uniform over the triangle's area.
      const double radial = std::sqrt(unitDouble(engine));
      const double across = unitDouble(engine);
      const Triangle3 &triangle = proper_[index];
      samples.points.push_back(triangle[0] + radial * (1.0 - across) * (triangle[1] - triangle[0]) +
                               radial * across * (triangle[2] - triangle[0]));
      samples.on_other.push_back(triangle_on_other[proper_source_[index]]);
    }
  }

  const std::vector<Eigen::Vector3d> &vertices_;
  const std::vector<Triangle> &usable_;
  std::vector<Triangle3> proper_;
  std::vector<std::size_t> proper_source_; // index into usable_
  std::vector<Segment3> collapsed_;
  TriangleTree triangle_tree_;
  SegmentTree segment_tree_;
};

/// Distances of one direction, normalised by the reference diagonal, and the
/// range the statistics use: every sample, or the area-uniform ones only.
struct SampledDistances {
  std::vector<double> distances; // deterministic samples first, random ones after
  std::size_t statistics_begin = 0;

  double shareWithin(double tolerance) const {
    const auto begin = distances.begin() + static_cast<std::ptrdiff_t>(statistics_begin);
    const auto within = std::count_if(
        begin, distances.end(), [tolerance](double distance) { return distance <= tolerance; });
    return static_cast<double>(within) / static_cast<double>(distances.end() - begin);
  }

  DistanceStats stats() const {
    DistanceStats result;
    result.max = *std::max_element(distances.begin(), distances.end());
    std::vector<double> tail(distances.begin() + static_cast<std::ptrdiff_t>(statistics_begin),
                             distances.end());
    result.mean = std::accumulate(tail.begin(), tail.end(), 0.0) / static_cast<double>(tail.size());
    // Nearest rank: the smallest value with at least 95 % of them at or below it.
    const auto rank = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(tail.size())));
    const auto nth = tail.begin() + static_cast<std::ptrdiff_t>(std::max<std::size_t>(rank, 1) - 1);
    std::nth_element(tail.begin(), nth, tail.end());
    result.p95 = *nth;
    return result;
  }
};

SampledDistances measure(const SampleSet &samples, Surface &to, const ReferenceOptions &options,
                         double scale) {
  SampledDistances result;
  result.distances = to.distances(samples);
  for (double &distance : result.distances)
    distance /= scale;
  if (options.area_weighted_statistics && samples.points.size() > samples.deterministic_count)
    result.statistics_begin = samples.deterministic_count;
  return result;
}

double fscore(double precision, double recall) {
  return precision + recall > 0 ? 2 * precision * recall / (precision + recall) : 0.0;
}

} // namespace

ReferenceReport compareWithReference(const std::vector<Eigen::Vector3d> &vertices,
                                     const std::vector<Triangle> &triangles,
                                     const std::vector<Eigen::Vector3d> &reference_vertices,
                                     const std::vector<Triangle> &reference_triangles,
                                     const ReferenceOptions &options) {
  ReferenceReport report;
  report.triangles = triangles.size();
  report.reference_triangles = reference_triangles.size();
  const std::vector<Triangle> usable = usableTriangles(vertices, triangles);
  const std::vector<Triangle> reference_usable =
      usableTriangles(reference_vertices, reference_triangles);

  if (!reference_usable.empty()) {
    Eigen::Vector3d low = reference_vertices[reference_usable.front()[0]], high = low;
    for (const Triangle &triangle : reference_usable)
      for (VertexIndex vertex : triangle) {
        low = low.cwiseMin(reference_vertices[vertex]);
        high = high.cwiseMax(reference_vertices[vertex]);
      }
    report.reference_diagonal = (high - low).norm();
  }

  // Coincidence, as triples of shared position ids.
  PositionIds positions(matchingPrecision(vertices, reference_vertices));
  const std::vector<VertexIndex> reference_ids =
      positions.assign(reference_vertices, reference_usable);
  positions.closeReference();
  const std::vector<VertexIndex> our_ids = positions.assign(vertices, usable);
  std::vector<Triangle> reference_keys, our_exact_keys;
  reference_keys.reserve(reference_usable.size());
  our_exact_keys.reserve(usable.size());
  for (const Triangle &triangle : reference_usable)
    reference_keys.push_back(keyOf(triangle, reference_ids));
  for (const Triangle &triangle : usable)
    our_exact_keys.push_back(keyOf(triangle, our_ids));

  // Triangle recovery: with a tolerance, our vertices are first moved onto
  // the ids of their nearest reference positions. Ids from
  // referenceCount() on are positions the reference does not have.
  std::vector<Triangle> our_match_keys = our_exact_keys;
  if (options.position_tolerance > 0) {
    const ToleranceMatcher matcher(reference_vertices, reference_ids, positions.referenceCount(),
                                   options.position_tolerance);
    std::vector<VertexIndex> matched(vertices.size(), kUnmatched);
    for (std::size_t vertex = 0; vertex < vertices.size(); ++vertex)
      if (our_ids[vertex] != kUnmatched)
        matched[vertex] = matcher.match(vertices[vertex]);
    for (std::size_t t = 0; t < usable.size(); ++t)
      our_match_keys[t] = keyOf(usable[t], matched);
  }
  const std::vector<char> recovered = occursIn(reference_keys, our_match_keys);
  const std::vector<char> in_reference = occursIn(our_match_keys, reference_keys);
  report.recovered_reference_triangles =
      static_cast<std::size_t>(std::count(recovered.begin(), recovered.end(), 1));
  report.triangles_in_reference =
      static_cast<std::size_t>(std::count(in_reference.begin(), in_reference.end(), 1));
  if (report.reference_triangles > 0)
    report.recall = static_cast<double>(report.recovered_reference_triangles) /
                    static_cast<double>(report.reference_triangles);
  if (report.triangles > 0)
    report.precision =
        static_cast<double>(report.triangles_in_reference) / static_cast<double>(report.triangles);

  Surface ours(vertices, usable);
  Surface reference(reference_vertices, reference_usable);
  if (ours.empty() || reference.empty()) {
    report.to_reference = report.from_reference = {kInfinity, kInfinity, kInfinity};
    return report;
  }

  // What lies exactly on the other mesh needs no distance query.
  std::vector<char> our_vertex_on_reference(vertices.size(), 0);
  std::vector<char> position_in_ours(positions.size(), 0);
  for (std::size_t vertex = 0; vertex < vertices.size(); ++vertex)
    if (our_ids[vertex] != kUnmatched) {
      our_vertex_on_reference[vertex] = our_ids[vertex] < positions.referenceCount();
      position_in_ours[our_ids[vertex]] = 1;
    }
  std::vector<char> reference_vertex_on_ours(reference_vertices.size(), 0);
  for (std::size_t vertex = 0; vertex < reference_vertices.size(); ++vertex)
    if (reference_ids[vertex] != kUnmatched)
      reference_vertex_on_ours[vertex] = position_in_ours[reference_ids[vertex]];
  const std::vector<char> our_triangle_on_reference = occursIn(our_exact_keys, reference_keys);
  const std::vector<char> reference_triangle_on_ours = occursIn(reference_keys, our_exact_keys);

  // Separate random streams so the two meshes are not sampled in lockstep.
  const SampleSet our_samples = ours.sample(our_vertex_on_reference, our_triangle_on_reference,
                                            options.surface_samples, options.seed, 0);
  const SampleSet reference_samples =
      reference.sample(reference_vertex_on_ours, reference_triangle_on_ours,
                       options.surface_samples, options.seed, 1);
  const double scale = report.reference_diagonal > 0 ? report.reference_diagonal : 1.0;
  const SampledDistances to_reference = measure(our_samples, reference, options, scale);
  const SampledDistances from_reference = measure(reference_samples, ours, options, scale);
  report.to_reference = to_reference.stats();
  report.from_reference = from_reference.stats();
  // With a zero diagonal the distances are absolute and tau is 0.
  const double tau_fine = report.reference_diagonal > 0 ? 0.001 : 0.0;
  const double tau_coarse = report.reference_diagonal > 0 ? 0.005 : 0.0;
  report.fscore_0_1 =
      fscore(to_reference.shareWithin(tau_fine), from_reference.shareWithin(tau_fine));
  report.fscore_0_5 =
      fscore(to_reference.shareWithin(tau_coarse), from_reference.shareWithin(tau_coarse));
  return report;
}

} // namespace pcl_ms
