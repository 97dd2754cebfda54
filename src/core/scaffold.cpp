// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 2, the medial scaffold (docs/algorithm.md section 2). In: distinct
// points. Out: a MedialScaffold, i.e. the candidate triangles (Delaunay
// facets within the local size limit) with their costs and neighbours, and
// each point's local scale.
#include <pcl_ms/costs.h>
#include <pcl_ms/reconstruct.h>
#include <pcl_ms/scaffold.h>

#include "corner_order.h"
#include "flat_cells.h"
#include "indexed_delaunay.h"
#include "populate_pages.h"
#include "threads.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <numeric>
#include <optional>

#include <tbb/info.h>

namespace pcl_ms {
namespace {

using detail::Delaunay;
using detail::Kernel;
using detail::KernelPoint;

// Cells per unit of parallel work. Chunks are fixed ranges of the cell order,
// so the output does not depend on how many threads process them.
constexpr std::size_t cells_per_chunk = 4096;

// A point's own scale is read where its smallest Gabriel triangles cover
// this much of a full turn around it (see measureLocalScales).
constexpr double scale_turn_fraction = 0.25;
// Rounds of the median over those triangles' corners.
constexpr int scale_smoothing_rounds = 2;
// The final round raises a point's scale to the largest around it, at most
// this many times its own median.
constexpr float scale_raise_cap = 2.0f;

// A vanishing shock length (co-spherical points) must not divide by zero.
constexpr double min_shock_length_fraction = 1e-6;

Eigen::Vector3d toEigen(const KernelPoint &p) { return {p.x(), p.y(), p.z()}; }

/// The three vertices of facet (cell, i), or false when one is infinite.
template <typename Triangulation>
bool facetVertices(const Triangulation &delaunay, typename Triangulation::Cell_handle cell, int i,
                   std::array<typename Triangulation::Vertex_handle, 3> &vertices) {
  for (int k = 0; k < 3; ++k) {
    vertices[k] = cell->vertex((i + 1 + k) & 3);
    if (delaunay.is_infinite(vertices[k]))
      return false;
  }
  return true;
}

/// Whether the facet's smallest circumscribing sphere has no Delaunay
/// neighbour strictly inside, decided with exact predicates: then the
/// circumcentre lies on the dual Voronoi edge (types I and II).
template <typename Triangulation>
bool isGabriel(const Triangulation &delaunay, typename Triangulation::Cell_handle cell, int i,
               const std::array<typename Triangulation::Vertex_handle, 3> &vertices) {
  const auto side_of_bounded_sphere = Kernel().side_of_bounded_sphere_3_object();
  for (const auto &apex : {cell->vertex(i), delaunay.mirror_vertex(cell, i)}) {
    if (delaunay.is_infinite(apex))
      continue;
    if (side_of_bounded_sphere(vertices[0]->point(), vertices[1]->point(), vertices[2]->point(),
                               apex->point()) == CGAL::ON_BOUNDED_SIDE)
      return false;
  }
  return true;
}

/// A facet's circumcircle as its shock length and normal term read it: the
/// radius, which the facet pass finds on its own, is not kept.
struct Circle {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d unit_normal = Eigen::Vector3d::Zero();
};

// Below this compactness the floating-point circumcentre may be off by more
// than the fast Gabriel test's margin: such needles go to the exact test.
constexpr double min_fast_gabriel_compactness = 1e-4;
// Relative gap between |apex - centre|^2 and radius^2 that rounding cannot
// bridge for triangles at least min_fast_gabriel_compactness compact.
constexpr double fast_gabriel_margin = 1e-6;

/// isGabriel() with a floating-point filter: the apexes are compared with
/// the circumcircle that the local scale needs anyway, and only near-ties
/// (or needles) pay for the exact predicate. Same answer, a fraction of the
/// time. `needle`: the facet is less compact than
/// min_fast_gabriel_compactness. The radius is given squared: most facets
/// are not Gabriel, and a square root would be waited for in vain.
template <typename Triangulation>
bool isGabriel(const Triangulation &delaunay, typename Triangulation::Cell_handle cell, int i,
               const std::array<typename Triangulation::Vertex_handle, 3> &vertices,
               const Eigen::Vector3d &centre, double radius_squared, bool needle) {
  if (needle)
    return isGabriel(delaunay, cell, i, vertices);
  const double margin = fast_gabriel_margin * radius_squared;
  for (const auto &apex : {cell->vertex(i), delaunay.mirror_vertex(cell, i)}) {
    if (delaunay.is_infinite(apex))
      continue;
    const KernelPoint &p = apex->point();
    const double distance_squared = (Eigen::Vector3d(p.x(), p.y(), p.z()) - centre).squaredNorm();
    if (distance_squared < radius_squared - margin)
      return false;
    if (distance_squared <= radius_squared + margin)
      return isGabriel(delaunay, cell, i, vertices);
  }
  return true;
}

/// Triangle a, b, c's edge vectors from a and their squared lengths: what
/// its circumcircle, its compactness and the collinearity filter share.
struct EdgeVectors {
  EdgeVectors(const Eigen::Vector3d &a, const Eigen::Vector3d &b, const Eigen::Vector3d &c)
      : u(b - a), v(c - a), w(u.cross(v)), uu(u.squaredNorm()), vv(v.squaredNorm()),
        ww(w.squaredNorm()) {}
  Eigen::Vector3d u, v, w; // b - a, c - a, u x v
  double uu, vv, ww;
};

/// The circumcentre of a triangle as an offset from its corner a, and the
/// squared circumradius (the offset's squared length).
struct CentreOffset {
  Eigen::Vector3d offset;
  double radius_squared;
};

/// The circumcentre of the triangle with corner a and edge vectors `edges`.
/// None where it does not exist in double precision, though the corners are
/// not collinear: edge vectors that round to parallel ones (a far corner
/// beside two close ones), or |u x v|^2 out of range. Callers leave such a
/// facet out as degenerate.
std::optional<CentreOffset> circumcentreOffset(const EdgeVectors &edges) {
  const Eigen::Vector3d offset =
      (edges.uu * edges.v.cross(edges.w) + edges.vv * edges.w.cross(edges.u)) / (2.0 * edges.ww);
  const double radius_squared = offset.squaredNorm();
  if (!std::isfinite(radius_squared))
    return std::nullopt;
  return CentreOffset{offset, radius_squared};
}

/// The circumcircle of the triangle with corner a, edge vectors `edges` and
/// circumcentre a + `found`.
Circle circleAt(const Eigen::Vector3d &a, const EdgeVectors &edges, const CentreOffset &found) {
  return Circle{a + found.offset, edges.w / std::sqrt(edges.ww)};
}

/// The circumcircle of the triangle with corner a and edge vectors `edges`,
/// where circumcentreOffset() finds its centre.
std::optional<Circle> circumcircle(const Eigen::Vector3d &a, const EdgeVectors &edges) {
  const std::optional<CentreOffset> found = circumcentreOffset(edges);
  if (!found)
    return std::nullopt;
  return circleAt(a, edges, *found);
}

// The candidates' pass reads the corner points and scales of the facets, in
// the triangulation's cell order: it fetches those of the facet this many
// steps ahead.
constexpr std::size_t corner_prefetch_distance = 8;

// Cells are visited in memory order, but their neighbours, which every
// facet test reads, lie anywhere: fetching the neighbours of the cell this
// many steps ahead hides most of the wait for them.
constexpr std::size_t neighbour_prefetch_distance = 8;

// Inlined by force, like every helper that only prefetches: GCC takes such a
// function for one without effects and drops the calls to it.
template <typename CellHandle>
[[gnu::always_inline]] inline void prefetchNeighbours(const std::vector<CellHandle> &cells,
                                                      std::size_t index) {
  if (index >= cells.size())
    return;
  for (int i = 0; i < 4; ++i) {
    const char *neighbour = reinterpret_cast<const char *>(&*cells[index]->neighbor(i));
    __builtin_prefetch(neighbour);
    __builtin_prefetch(neighbour + 64);
    __builtin_prefetch(&*cells[index]->vertex(i));
  }
}

std::size_t chunkCount(std::size_t items) {
  return (items + cells_per_chunk - 1) / cells_per_chunk;
}

template <typename ChunkWork>
void forEachChunk(std::size_t items, int num_threads, const ChunkWork &work) {
  detail::withThreads(num_threads, [&] {
    detail::parallelFor(std::size_t(0), chunkCount(items), [&](std::size_t chunk) {
      work(chunk, chunk * cells_per_chunk, std::min(items, (chunk + 1) * cells_per_chunk));
    });
  });
}

/// The median of [first, last), reordering it; 0 when empty.
template <typename Iterator> float medianOf(Iterator first, Iterator last) {
  if (first == last)
    return 0;
  const Iterator middle = first + (last - first) / 2;
  std::nth_element(first, middle, last);
  return *middle;
}

double median(std::vector<float> &values) { return medianOf(values.begin(), values.end()); }

/// What the local scales' pass finds out about a facet, for the candidates'.
/// The Gabriel facets of a 3-D triangulation come out typed (acute, obtuse)
/// with their shock length; a facet whose circumcircle does not exist in
/// double precision counts as collinear.
enum class FacetKind : std::uint8_t { collinear, acute, obtuse, gabriel_planar, other };

/// The finite facets of one chunk of cells, in the order visited: what the
/// candidates' pass reads instead of the triangulation, so that it runs
/// after the tetrahedra are freed.
struct ChunkFacets {
  std::vector<Triangle> corners; // ascending
  std::vector<FacetKind> kinds;
  std::vector<double> shock_lengths; // one per acute or obtuse facet
};

/// Whether a facet of this kind was typed: its shock length was measured.
bool isTyped(FacetKind kind) { return kind == FacetKind::acute || kind == FacetKind::obtuse; }

// |u x v|^2 above this times |u|^2 |v|^2 (a sine above 1e-10) cannot come
// from rounding (about 1e-15 relative): those facets skip the exact test.
constexpr double surely_not_collinear = 1e-20;

// A dot product whose square exceeds this times |x|^2 |y|^2 has the sign of
// the exact one.
constexpr double surely_signed = 1e-24;

/// Whether every angle of the facet is acute, decided exactly: the
/// floating-point dot products where their sign is certain, CGAL's exact
/// test for the rest. a, b, c are the coordinates of the handles' points, in
/// any order.
template <typename Handle>
bool allAnglesAcute(const Eigen::Vector3d &a, const Eigen::Vector3d &b, const Eigen::Vector3d &c,
                    const std::array<Handle, 3> &handles) {
  const Eigen::Vector3d ab = b - a, bc = c - b, ca = a - c;
  const double ab2 = ab.squaredNorm(), bc2 = bc.squaredNorm(), ca2 = ca.squaredNorm();
  // The angles at a, b and c.
  const double dots[3] = {-ab.dot(ca), -bc.dot(ab), -ca.dot(bc)};
  const double scales[3] = {ab2 * ca2, bc2 * ab2, ca2 * bc2};
  bool certain = true;
  for (int k = 0; k < 3; ++k) {
    if (!(dots[k] * dots[k] > surely_signed * scales[k]))
      certain = false;
    else if (dots[k] < 0)
      return false;
  }
  if (certain)
    return true;
  return CGAL::angle(handles[2]->point(), handles[0]->point(), handles[1]->point()) ==
             CGAL::ACUTE &&
         CGAL::angle(handles[0]->point(), handles[1]->point(), handles[2]->point()) ==
             CGAL::ACUTE &&
         CGAL::angle(handles[1]->point(), handles[2]->point(), handles[0]->point()) == CGAL::ACUTE;
}

/// What the candidates' pass makes of a facet, decided before any is costed
/// so that each candidate is written once, in its final place.
enum class FacetFate : std::uint8_t { left_out, oversize, degenerate, gabriel, ambiguous };

/// Per chunk of facets: each one's fate and how many have each.
struct ChunkFates {
  std::vector<FacetFate> fates;
  std::size_t counts[5] = {0, 0, 0, 0, 0}; // by FacetFate
};

/// A Gabriel facet as the local scales read it: corners ascending.
struct GabrielTriangle {
  std::array<VertexIndex, 3> corners;
  float circumradius;
};

class ScaffoldBuilder {
public:
  ScaffoldBuilder(const std::vector<Eigen::Vector3d> &points, const ScaffoldOptions &options)
      : points_(points), options_(options) {}

  MedialScaffold build() {
    const auto start = std::chrono::steady_clock::now();
    if (triangulatesInParallel()) {
      detail::ParallelTriangulation parallel(points_);
      {
        const std::vector<detail::IndexedPoint> input = detail::indexedPoints(points_);
        detail::withThreads(options_.num_threads, [&] { parallel.insert(input); });
      }
      scaffold_.parallel_triangulation = true;
      listFacets(parallel.delaunay, start);
    } else {
      Delaunay delaunay = triangulate();
      listFacets(delaunay, start);
    }
    measureLocalScales();
    buildCandidates();
    chunk_facets_ = {};
    if (options_.fixed_triangles)
      addFixedTriangles(*options_.fixed_triangles);
    if (options_.preferred_triangles)
      addPreferredTriangles(*options_.preferred_triangles);
    buildEdgeGraph();
    return std::move(scaffold_);
  }

private:
  /// On several threads the triangulation is built by CGAL's parallel
  /// insertion: from 6,000 points on (fewer run on one thread) it took
  /// 0.76-0.84 times the sequential one's time on two (bench/README.md).
  /// The scaffold does not depend on which one is built.
  bool triangulatesInParallel() const {
    const int threads =
        options_.num_threads > 0 ? options_.num_threads : tbb::info::default_concurrency();
    return threads > 1;
  }

  /// Lists the triangulation's facets with what the candidates need of each
  /// (chunk_facets_) and its Gabriel triangles (chunk_triangles_), then frees the
  /// tetrahedra. `start`: when the triangulation began.
  template <typename Triangulation>
  void listFacets(Triangulation &delaunay, std::chrono::steady_clock::time_point start) {
    scaffold_.delaunay_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (delaunay.dimension() < 2)
      throw ReconstructionError("all points are collinear: no surface can be built");
    scaffold_.planar = delaunay.dimension() == 2;
    std::vector<typename Triangulation::Cell_handle> cells = collectCells(delaunay);
    listFacetsOfCells(delaunay, cells);
    // The facets are listed: the tetrahedra are no longer needed.
    cells = {};
    delaunay.clear();
  }

  Delaunay triangulate() const {
    std::vector<detail::IndexedPoint> input = detail::indexedPoints(points_);
    // Inserted in spatial order; symbolic perturbation makes the
    // triangulation unique even for co-spherical points.
    Delaunay delaunay;
    detail::insertIndexed(delaunay, input);
    return delaunay;
  }

  /// Numbers the cells (ids decide which of two cells owns a shared facet)
  /// and lists them in a fixed order for chunked processing.
  template <typename Triangulation>
  std::vector<typename Triangulation::Cell_handle> collectCells(const Triangulation &delaunay) {
    std::vector<typename Triangulation::Cell_handle> cells;
    if (scaffold_.planar) {
      // In dimension 2 each finite face is stored as a cell of its own.
      for (auto facet = delaunay.finite_facets_begin(); facet != delaunay.finite_facets_end();
           ++facet)
        cells.push_back(facet->first);
      return cells;
    }
    std::uint32_t id = 0;
    cells.reserve(delaunay.tds().number_of_cells());
    detail::populateCapacity(cells);
    for (auto cell : delaunay.all_cell_handles()) {
      cell->info() = id++;
      cells.push_back(cell);
    }
    return cells;
  }

  /// Calls visit(cell, i, vertices) once for every finite facet owned by cell.
  template <typename Triangulation, typename Visit>
  void forEachOwnedFacet(const Triangulation &delaunay, typename Triangulation::Cell_handle cell,
                         const Visit &visit) const {
    std::array<typename Triangulation::Vertex_handle, 3> vertices;
    if (scaffold_.planar) {
      vertices = {cell->vertex(0), cell->vertex(1), cell->vertex(2)};
      visit(cell, 3, vertices);
      return;
    }
    for (int i = 0; i < 4; ++i) {
      // Each facet is shared by two cells: the one with the smaller id owns it.
      if (cell->info() > cell->neighbor(i)->info())
        continue;
      if (facetVertices(delaunay, cell, i, vertices))
        visit(cell, i, vertices);
    }
  }

  /// The facet pass: every finite facet once, in chunks of cells, with its
  /// corners, kind and shock length (chunk_facets_), and the Gabriel ones
  /// with their circumradii (chunk_triangles_).
  template <typename Triangulation>
  void listFacetsOfCells(const Triangulation &delaunay,
                         const std::vector<typename Triangulation::Cell_handle> &cells) {
    using VertexHandle = typename Triangulation::Vertex_handle;
    chunk_triangles_.assign(chunkCount(cells.size()), {});
    chunk_facets_.assign(chunkCount(cells.size()), {});
    forEachChunk(
        cells.size(), options_.num_threads,
        [&](std::size_t chunk, std::size_t begin, std::size_t end) {
          // Filled with room for every facet the cells can own (4 a cell, 1
          // in a plane), then kept at their exact sizes: grown by doubling,
          // the lists' copies took a sixth of a call's page faults
          // (bench/README.md, "Pages faulted in before the first write").
          const std::size_t most_facets = (scaffold_.planar ? 1 : 4) * (end - begin);
          ChunkFacets facets;
          std::vector<GabrielTriangle> gabriel;
          facets.corners.reserve(most_facets);
          facets.kinds.reserve(most_facets);
          facets.shock_lengths.reserve(most_facets);
          gabriel.reserve(most_facets);
          std::vector<FacetKind> &kinds = facets.kinds;
          for (std::size_t index = begin; index < end; ++index) {
            if (!scaffold_.planar)
              prefetchNeighbours(cells, index + neighbour_prefetch_distance);
            forEachOwnedFacet(delaunay, cells[index], [&](auto cell, int i, const auto &vertices) {
              // Everything below is computed from the corners in
              // ascending order, so the candidates do not depend on the
              // order in which the triangulation stores cells and their
              // vertices (docs/algorithm.md, "Candidate order").
              const std::array<VertexHandle, 3> ordered = detail::byIndex(vertices);
              const Triangle sorted = {ordered[0]->info(), ordered[1]->info(), ordered[2]->info()};
              facets.corners.push_back(sorted);
              const Eigen::Vector3d a = toEigen(ordered[0]->point()),
                                    b = toEigen(ordered[1]->point()),
                                    c = toEigen(ordered[2]->point());
              const EdgeVectors edges(a, b, c);
              if (!(edges.ww > surely_not_collinear * edges.uu * edges.vv) &&
                  CGAL::collinear(ordered[0]->point(), ordered[1]->point(), ordered[2]->point())) {
                kinds.push_back(FacetKind::collinear);
                return;
              }
              const std::optional<CentreOffset> circle = circumcentreOffset(edges);
              if (!circle) { // left out like a collinear facet
                kinds.push_back(FacetKind::collinear);
                return;
              }
              // Compactness 4 sqrt(3) A / (d1^2 + d2^2 + d3^2), A = |w| / 2,
              // compared squared: no root, no division.
              const double sum_of_squares = edges.uu + edges.vv + (edges.v - edges.u).squaredNorm();
              const bool needle = 12 * edges.ww < min_fast_gabriel_compactness *
                                                      min_fast_gabriel_compactness *
                                                      sum_of_squares * sum_of_squares;
              const bool is_gabriel =
                  scaffold_.planar || isGabriel(delaunay, cell, i, ordered, a + circle->offset,
                                                circle->radius_squared, needle);
              if (!is_gabriel) {
                kinds.push_back(FacetKind::other);
                return;
              }
              gabriel.push_back({sorted, static_cast<float>(std::sqrt(circle->radius_squared))});
              if (scaffold_.planar) {
                kinds.push_back(FacetKind::gabriel_planar);
                return;
              }
              facets.shock_lengths.push_back(
                  shockLength(delaunay, cell, i, circleAt(a, edges, *circle)));
              kinds.push_back(allAnglesAcute(a, b, c, ordered) ? FacetKind::acute
                                                               : FacetKind::obtuse);
            });
          }
          chunk_facets_[chunk] = {detail::exactCopy(facets.corners), detail::exactCopy(kinds),
                                  detail::exactCopy(facets.shock_lengths)};
          chunk_triangles_[chunk] = detail::exactCopy(gabriel);
        });
  }

  /// Each point's local scale (docs/algorithm.md, "Local scale"): the
  /// typical circumradius of the surface triangles where it lies. Points
  /// given a scale in ScaffoldOptions::local_scale keep it.
  ///
  /// 1. A point's own value: its Gabriel triangles (types I and II; all
  ///    triangles in the planar case), smallest first, until their angles at
  ///    the point cover a quarter turn; the circumradius reached then. At the
  ///    rim of a hole, where Gabriel triangles also span the hole, the
  ///    quarter turn is covered by the surface's own small triangles.
  /// 2. The scale: the median of the own values of the point and of the
  ///    corners of the triangles that made up its quarter turn, so that one
  ///    odd point does not decide; then the same median of these medians.
  ///    Last, the largest of these over the same neighbours, capped at twice
  ///    the point's own: medians of small neighbourhoods keep the tight
  ///    clusters of a random sample at a third of the scale around them,
  ///    and the surface had holes there.
  /// 3. One factor for the whole cloud makes the median scale the median
  ///    Gabriel circumradius, d_med: on a uniform sample every scale is about
  ///    d_med, and rho keeps the meaning it had with one global length.
  void measureLocalScales() {
    const std::size_t n = points_.size();
    std::vector<std::vector<GabrielTriangle>> chunk_triangles = std::move(chunk_triangles_);
    // Each point's Gabriel triangles (CSR): their circumradii and, two per
    // triangle, the other corners.
    std::vector<std::uint32_t> offsets(n + 1, 0);
    std::vector<float> circumradii;
    std::size_t gabriel_count = 0;
    for (const auto &gabriel : chunk_triangles)
      gabriel_count += gabriel.size();
    circumradii.reserve(gabriel_count);
    for (const auto &gabriel : chunk_triangles)
      for (const GabrielTriangle &triangle : gabriel) {
        circumradii.push_back(triangle.circumradius);
        for (VertexIndex v : triangle.corners)
          ++offsets[v + 1];
      }
    if (circumradii.empty())
      throw ReconstructionError("all points are collinear: no surface can be built");
    if (options_.local_scale && options_.local_scale->size() == n &&
        std::all_of(options_.local_scale->begin(), options_.local_scale->end(),
                    [](float scale) { return scale > 0; })) {
      // Every scale given (a seam zone's points, all from meshed buckets):
      // nothing below would be used but d_med.
      scaffold_.d_med = options_.d_med > 0 ? options_.d_med : median(circumradii);
      scaffold_.d_max = options_.rho * scaffold_.d_med;
      scaffold_.local_scale = *options_.local_scale;
      return;
    }
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    std::vector<float> radii_at;
    std::vector<VertexIndex> corners_at;
    detail::resizeForWriting(radii_at, offsets[n]);
    detail::resizeForWriting(corners_at, 2 * std::size_t{offsets[n]});
    {
      std::vector<std::uint32_t> cursor(offsets.begin(), offsets.end() - 1);
      for (auto &gabriel : chunk_triangles) {
        for (const GabrielTriangle &triangle : gabriel)
          for (int k = 0; k < 3; ++k) {
            const std::uint32_t slot = cursor[triangle.corners[k]]++;
            corners_at[2 * std::size_t{slot}] = triangle.corners[(k + 1) % 3];
            corners_at[2 * std::size_t{slot} + 1] = triangle.corners[(k + 2) % 3];
            radii_at[slot] = triangle.circumradius;
          }
        gabriel = {};
      }
    }
    auto cornersOf = [&](std::uint32_t slot) {
      return std::make_pair(corners_at[2 * std::size_t{slot}],
                            corners_at[2 * std::size_t{slot} + 1]);
    };
    // Step 1. 0 marks a point on no Gabriel triangle (rare: each of its
    // triangles has a neighbour inside its diametral sphere). Angles are
    // computed smallest triangle first, only until the quarter turn is
    // covered; the value reached does not depend on the order of equal radii.
    std::vector<float> own(n, 0.0f);
    forEachChunk(n, options_.num_threads, [&](std::size_t, std::size_t begin, std::size_t end) {
      std::vector<std::pair<float, std::uint32_t>> by_size; // (circumradius, slot)
      for (std::size_t v = begin; v < end; ++v) {
        by_size.clear();
        for (std::uint32_t slot = offsets[v]; slot < offsets[v + 1]; ++slot)
          by_size.emplace_back(radii_at[slot], slot);
        std::sort(by_size.begin(), by_size.end(), [&](const auto &x, const auto &y) {
          return x.first != y.first ? x.first < y.first : cornersOf(x.second) < cornersOf(y.second);
        });
        double covered = 0;
        for (const auto &[radius, slot] : by_size) {
          own[v] = radius;
          const auto [b, c] = cornersOf(slot);
          const Eigen::Vector3d to_b = points_[b] - points_[v], to_c = points_[c] - points_[v];
          covered += std::atan2(to_b.cross(to_c).norm(), to_b.dot(to_c));
          if (covered >= scale_turn_fraction * 2 * M_PI)
            break;
        }
      }
    });
    // Step 2, twice: once is not enough to tame the spread of a random
    // sample's own values, which left holes in the sparse parts of the test
    // clouds and let one inflated corner stretch a triangle across a depth
    // jump (docs/algorithm.md).
    std::vector<float> &scale = scaffold_.local_scale;
    std::vector<float> previous = own;
    scale.assign(n, 0.0f);
    for (int round = 0; round < scale_smoothing_rounds; ++round) {
      forEachChunk(n, options_.num_threads, [&](std::size_t, std::size_t begin, std::size_t end) {
        std::vector<float> around;
        for (std::size_t v = begin; v < end; ++v) {
          around.clear();
          if (previous[v] > 0)
            around.push_back(previous[v]);
          for (std::uint32_t slot = offsets[v]; slot < offsets[v + 1]; ++slot) {
            if (radii_at[slot] > own[v])
              continue; // not one of the triangles of its quarter turn
            const auto [b, c] = cornersOf(slot);
            for (VertexIndex corner : {b, c})
              if (previous[corner] > 0)
                around.push_back(previous[corner]);
          }
          scale[v] = medianOf(around.begin(), around.end());
        }
      });
      previous = scale;
    }
    // Then the raise, capped so that a dense point beside sparse strays (a
    // scan's silhouette) does not take their scale.
    forEachChunk(n, options_.num_threads, [&](std::size_t, std::size_t begin, std::size_t end) {
      for (std::size_t v = begin; v < end; ++v) {
        float largest = previous[v];
        for (std::uint32_t slot = offsets[v]; slot < offsets[v + 1]; ++slot)
          if (radii_at[slot] <= own[v]) {
            const auto [b, c] = cornersOf(slot);
            largest = std::max({largest, previous[b], previous[c]});
          }
        scale[v] = std::min(largest, scale_raise_cap * previous[v]);
      }
    });
    previous = {};
    radii_at = {};
    corners_at = {};
    // Step 3.
    std::vector<float> measured;
    measured.reserve(n);
    for (float value : scale)
      if (value > 0)
        measured.push_back(value);
    const double median_circumradius = median(circumradii);
    const double median_scale = median(measured);
    scaffold_.d_med = options_.d_med > 0 ? options_.d_med : median_circumradius;
    scaffold_.d_max = options_.rho * scaffold_.d_med;
    const double calibration = median_scale > 0 ? median_circumradius / median_scale : 1.0;
    for (std::size_t v = 0; v < n; ++v) {
      if (options_.local_scale && (*options_.local_scale)[v] > 0)
        scale[v] = (*options_.local_scale)[v];
      else
        scale[v] = scale[v] > 0 ? static_cast<float>(scale[v] * calibration)
                                : static_cast<float>(scaffold_.d_med);
    }
  }

  /// The shorter piece of the dual Voronoi edge cut by the circumcentre.
  template <typename Triangulation>
  double shockLength(const Triangulation &delaunay, typename Triangulation::Cell_handle cell, int i,
                     const Circle &circle) const {
    double shortest = std::numeric_limits<double>::infinity();
    for (const auto side : {cell, cell->neighbor(i)}) {
      Eigen::Vector3d voronoi_vertex;
      if (delaunay.is_infinite(side) || !detail::circumcentre(side, voronoi_vertex.data()))
        continue; // that piece is a ray (or as long as one): infinitely long
      shortest =
          std::min(shortest, std::abs((voronoi_vertex - circle.centre).dot(circle.unit_normal)));
    }
    return shortest;
  }

  /// Mean |n_T . n_v| over the vertices with a usable (non-zero) normal.
  double normalAgreement(const std::array<VertexIndex, 3> &ids,
                         const Eigen::Vector3d &unit_normal) const {
    double sum = 0;
    int usable = 0;
    for (VertexIndex id : ids) {
      const Eigen::Vector3d normal = (*options_.normals)[id].cast<double>();
      if (normal.squaredNorm() == 0)
        continue;
      sum += std::abs(unit_normal.dot(normal));
      ++usable;
    }
    return usable ? sum / usable : 1.0;
  }

  /// The candidates, types I and II first (pass 1 of the greedy touches only
  /// them, so its working set is a contiguous part of the list) in the
  /// order of their corners (docs/algorithm.md, "Candidate order"), type III
  /// after them in the facets' order. Two steps over the facets: their
  /// fates, then the costs of those that become candidates, each written
  /// once in its place. A list per chunk copied into the whole one took
  /// longer: twice the fresh memory, each page of it a fault
  /// (bench/README.md).
  void buildCandidates() {
    // Types I and II go by lowest corner (a counting sort): next_gabriel[v]
    // counts those whose lowest corner is v - 1, then, summed, is where the
    // next one whose lowest corner is v goes.
    const std::size_t n = points_.size();
    std::vector<std::uint32_t> next_gabriel(n + 1, 0), next_ambiguous(n + 1, 0);
    std::vector<ChunkFates> chunks(chunk_facets_.size());
    forEachFacetChunk([&](std::size_t chunk) {
      const ChunkFacets &facets = chunk_facets_[chunk];
      ChunkFates &out = chunks[chunk];
      out.fates.resize(facets.kinds.size());
      for (std::size_t f = 0; f < facets.kinds.size(); ++f) {
        prefetchCorners(facets, f + corner_prefetch_distance);
        const FacetFate fate = fateOf(facets.corners[f], facets.kinds[f]);
        out.fates[f] = fate;
        ++out.counts[static_cast<int>(fate)];
        if (fate == FacetFate::gabriel)
          detail::countUp(next_gabriel[facets.corners[f][0] + 1]);
        else if (fate == FacetFate::ambiguous)
          detail::countUp(next_ambiguous[facets.corners[f][0] + 1]);
      }
    });
    std::size_t gabriel_total = 0, ambiguous_total = 0;
    for (std::size_t chunk = 0; chunk < chunks.size(); ++chunk) {
      gabriel_total += chunks[chunk].counts[static_cast<int>(FacetFate::gabriel)];
      ambiguous_total += chunks[chunk].counts[static_cast<int>(FacetFate::ambiguous)];
      scaffold_.oversize += chunks[chunk].counts[static_cast<int>(FacetFate::oversize)];
      scaffold_.degenerate += chunks[chunk].counts[static_cast<int>(FacetFate::degenerate)];
    }
    std::vector<Candidate> &candidates = scaffold_.candidates;
    detail::resizeForWriting(candidates, gabriel_total + ambiguous_total);
    std::partial_sum(next_gabriel.begin(), next_gabriel.end(), next_gabriel.begin());
    next_ambiguous[0] = static_cast<std::uint32_t>(gabriel_total);
    std::partial_sum(next_ambiguous.begin(), next_ambiguous.end(), next_ambiguous.begin());
    std::vector<std::array<std::size_t, 4>> type_counts(chunks.size(), {0, 0, 0, 0});
    forEachFacetChunk([&](std::size_t chunk) {
      const ChunkFacets &facets = chunk_facets_[chunk];
      const std::vector<FacetFate> &fates = chunks[chunk].fates;
      std::vector<double>::const_iterator next_shock_length = facets.shock_lengths.begin();
      for (std::size_t f = 0; f < fates.size(); ++f) {
        const FacetKind kind = facets.kinds[f];
        const double measured_shock_length = isTyped(kind) ? *next_shock_length++ : 0.0;
        if (fates[f] != FacetFate::gabriel && fates[f] != FacetFate::ambiguous)
          continue;
        prefetchCorners(facets, f + corner_prefetch_distance);
        // Chunks on other threads may share a lowest corner: the slot is
        // taken atomically, and the order it gives is undone by the sort
        // below.
        Candidate &candidate = candidates[detail::countUp((
            fates[f] == FacetFate::gabriel ? next_gabriel : next_ambiguous)[facets.corners[f][0]])];
        cost(facets.corners[f], kind, measured_shock_length, candidate);
        ++type_counts[chunk][static_cast<int>(candidate.type)];
      }
    });
    // Now next_gabriel[v] is where lowest corner v's candidates end, and the
    // next smaller corner's end is where they begin: the few of each corner
    // are sorted by their other two.
    forEachChunk(n, options_.num_threads, [&](std::size_t, std::size_t begin, std::size_t end) {
      auto byCorners = [](const Candidate &a, const Candidate &b) {
        return a.vertices < b.vertices;
      };
      for (std::size_t v = begin; v < end; ++v) {
        std::sort(candidates.begin() + (v > 0 ? next_gabriel[v - 1] : 0),
                  candidates.begin() + next_gabriel[v], byCorners);
        std::sort(candidates.begin() + (v > 0 ? next_ambiguous[v - 1] : gabriel_total),
                  candidates.begin() + next_ambiguous[v], byCorners);
      }
    });
    for (const auto &counts : type_counts) {
      scaffold_.type1 += counts[1];
      scaffold_.type2 += counts[2];
      scaffold_.type3 += counts[3];
    }
  }

  template <typename ChunkWork> void forEachFacetChunk(const ChunkWork &work) const {
    detail::withThreads(options_.num_threads,
                        [&] { detail::parallelFor(std::size_t(0), chunk_facets_.size(), work); });
  }

  [[gnu::always_inline]] inline void prefetchCorners(const ChunkFacets &facets,
                                                     std::size_t f) const {
    if (f >= facets.corners.size())
      return;
    for (VertexIndex corner : facets.corners[f]) {
      __builtin_prefetch(&points_[corner]);
      __builtin_prefetch(&scaffold_.local_scale[corner]);
    }
  }

  /// Whether a facet becomes a candidate, of which group, or why not.
  FacetFate fateOf(const Triangle &corners, FacetKind kind) const {
    if (touchesFrozenVertex(corners))
      return FacetFate::left_out;
    const Eigen::Vector3d &a = points_[corners[0]], &b = points_[corners[1]],
                          &c = points_[corners[2]];
    // About half the facets of a surface sample's tetrahedra are too long:
    // the cheap length test comes first.
    const double max_side = options_.rho * triangleScale(scaffold_.local_scale, corners);
    if (std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()}) >=
        max_side * max_side)
      return FacetFate::oversize;
    if (kind == FacetKind::collinear)
      return FacetFate::degenerate;
    // The normal term needs the circle's normal (a typed facet's was found).
    if (options_.normals && !isTyped(kind) && !circumcircle(a, EdgeVectors(a, b, c)))
      return FacetFate::degenerate;
    return kind == FacetKind::other ? FacetFate::ambiguous : FacetFate::gabriel;
  }

  /// The type and costs of a facet whose fate is to be a candidate.
  void cost(const Triangle &corners, FacetKind kind, double measured_shock_length,
            Candidate &candidate) const {
    candidate.vertices = corners;
    const Eigen::Vector3d &a = points_[corners[0]], &b = points_[corners[1]],
                          &c = points_[corners[2]];
    const double local_scale = triangleScale(scaffold_.local_scale, corners);
    const TriangleShape shape = triangleShape(a, b, c);
    double shock_length;
    if (isTyped(kind)) {
      candidate.type = kind == FacetKind::acute ? CandidateType::acute : CandidateType::obtuse;
      shock_length = measured_shock_length;
    } else if (kind == FacetKind::gabriel_planar) {
      // Both Voronoi pieces are infinite in a plane: rank by shape and size.
      candidate.type = CandidateType::acute;
      shock_length = local_scale;
    } else {
      // Type III has no A1^3-2 point on its curve: use the local spacing.
      candidate.type = CandidateType::ambiguous;
      shock_length = local_scale;
    }
    shock_length = std::max(shock_length, min_shock_length_fraction * local_scale);
    const double compactness_squared = shape.compactness * shape.compactness;
    double base_cost = baseCost(shape.perimeter, shock_length, shape.compactness);
    if (options_.normals) {
      // Found: fateOf let the facet through only then.
      const Eigen::Vector3d unit_normal = circumcircle(a, EdgeVectors(a, b, c))->unit_normal;
      base_cost *= 1.0 + options_.normal_weight * (1.0 - normalAgreement(corners, unit_normal));
    }
    candidate.base_cost = static_cast<float>(base_cost);
    candidate.inverse_shock_compactness =
        static_cast<float>(1.0 / (shock_length * compactness_squared));
    candidate.edges = {0, 0, 0};
  }

  bool touchesFrozenVertex(const std::array<VertexIndex, 3> &vertices) const {
    if (!options_.frozen_vertices)
      return false;
    for (VertexIndex v : vertices)
      if ((*options_.frozen_vertices)[v])
        return true;
    return false;
  }

  /// Finds each fixed triangle among the candidates, appending those that
  /// are missing (not Delaunay here, too long, or on a frozen vertex).
  void addFixedTriangles(const std::vector<Triangle> &fixed) {
    std::vector<std::pair<Triangle, std::size_t>> sorted(fixed.size());
    for (std::size_t i = 0; i < fixed.size(); ++i) {
      sorted[i] = {fixed[i], i};
      std::sort(sorted[i].first.begin(), sorted[i].first.end());
    }
    std::sort(sorted.begin(), sorted.end());
    scaffold_.fixed.assign(fixed.size(), no_fixed_candidate);
    for (CandidateIndex t = 0; t < scaffold_.candidates.size(); ++t) {
      const Triangle &vertices = scaffold_.candidates[t].vertices;
      auto it =
          std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(vertices, std::size_t{0}));
      for (; it != sorted.end() && it->first == vertices; ++it)
        scaffold_.fixed[it->second] = t;
    }
    for (std::size_t i = 0; i < sorted.size(); ++i) {
      const auto &[vertices, position] = sorted[i];
      if (scaffold_.fixed[position] != no_fixed_candidate)
        continue;
      if (i > 0 && sorted[i - 1].first == vertices) { // listed twice: one candidate
        scaffold_.fixed[position] = scaffold_.fixed[sorted[i - 1].second];
        continue;
      }
      Candidate candidate;
      candidate.vertices = vertices;
      candidate.edges = {0, 0, 0};
      // Never ranked: it is in the surface from the start.
      candidate.base_cost = 0;
      candidate.inverse_shock_compactness = 0;
      candidate.type = CandidateType::acute;
      scaffold_.fixed[position] = static_cast<CandidateIndex>(scaffold_.candidates.size());
      scaffold_.candidates.push_back(candidate);
    }
  }

  static constexpr CandidateIndex no_fixed_candidate = std::numeric_limits<CandidateIndex>::max();

  /// Finds each preferred triangle (distinct, corners ascending) among the
  /// candidates and appends the missing ones that are neither oversize nor
  /// degenerate (docs/algorithm.md, "Initial triangles"). An appended one is
  /// costed like a type III candidate, with the local scale for R: the
  /// greedy ranks the preferred ones by that cost among themselves.
  void addPreferredTriangles(const std::vector<Triangle> &preferred) {
    std::vector<Triangle> sorted = preferred;
    std::sort(sorted.begin(), sorted.end());
    std::vector<bool> found(sorted.size(), false);
    for (CandidateIndex t = 0; t < scaffold_.candidates.size(); ++t) {
      const auto it =
          std::lower_bound(sorted.begin(), sorted.end(), scaffold_.candidates[t].vertices);
      if (it != sorted.end() && *it == scaffold_.candidates[t].vertices) {
        found[static_cast<std::size_t>(it - sorted.begin())] = true;
        scaffold_.preferred.push_back(t);
      }
    }
    const std::vector<float> &scale = scaffold_.local_scale;
    for (std::size_t i = 0; i < sorted.size(); ++i) {
      if (found[i])
        continue;
      const Triangle &vertices = sorted[i];
      const Eigen::Vector3d &a = points_[vertices[0]], &b = points_[vertices[1]],
                            &c = points_[vertices[2]];
      const double local_scale = triangleScale(scale, vertices);
      const TriangleShape shape = triangleShape(a, b, c);
      if (shape.longest_side >= options_.rho * local_scale) {
        ++scaffold_.preferred_oversize;
        continue;
      }
      if (CGAL::collinear(KernelPoint(a.x(), a.y(), a.z()), KernelPoint(b.x(), b.y(), b.z()),
                          KernelPoint(c.x(), c.y(), c.z())) ||
          !(shape.compactness > 0)) {
        ++scaffold_.preferred_degenerate;
        continue;
      }
      Candidate candidate;
      candidate.vertices = vertices;
      candidate.edges = {0, 0, 0};
      const double compactness_squared = shape.compactness * shape.compactness;
      candidate.base_cost =
          static_cast<float>(baseCost(shape.perimeter, local_scale, shape.compactness));
      candidate.inverse_shock_compactness =
          static_cast<float>(1.0 / (local_scale * compactness_squared));
      candidate.type = CandidateType::acute;
      scaffold_.preferred.push_back(static_cast<CandidateIndex>(scaffold_.candidates.size()));
      scaffold_.candidates.push_back(candidate);
    }
  }

  /// Numbers the edges of the candidates pass 1 looks at (types I and II,
  /// fixed ones) and lists those candidates on each edge. The other type III
  /// candidates keep no_edge: numbering and listing them would cost most of
  /// this stage, and only a few reach pass 2.
  void buildEdgeGraph() {
    std::vector<Candidate> &candidates = scaffold_.candidates;
    const std::size_t n = points_.size();
    std::vector<bool> in_graph(candidates.size());
    for (CandidateIndex t = 0; t < candidates.size(); ++t)
      in_graph[t] = candidates[t].type != CandidateType::ambiguous;
    // Fixed triangles are in the mesh from the start, whatever their type;
    // preferred ones are ranked in pass 1.
    for (CandidateIndex t : scaffold_.fixed)
      in_graph[t] = true;
    for (CandidateIndex t : scaffold_.preferred)
      in_graph[t] = true;
    for (CandidateIndex t = 0; t < candidates.size(); ++t)
      if (!in_graph[t])
        candidates[t].edges = {no_edge, no_edge, no_edge};
    // Neighbours b > a of every vertex a, via counting sort then per-vertex dedup.
    std::vector<std::uint32_t> offsets(n + 1, 0);
    auto forEachEdge = [&](auto &&visit) {
      for (CandidateIndex t = 0; t < candidates.size(); ++t) {
        if (!in_graph[t])
          continue;
        const auto &v = candidates[t].vertices;
        visit(t, 0, v[0], v[1]);
        visit(t, 1, v[1], v[2]);
        visit(t, 2, v[0], v[2]);
      }
    };
    forEachEdge([&](CandidateIndex, int, VertexIndex low, VertexIndex) { ++offsets[low + 1]; });
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    std::vector<VertexIndex> &neighbours = scaffold_.edge_high_vertices;
    neighbours.assign(offsets[n], 0);
    {
      std::vector<std::uint32_t> cursor(offsets.begin(), offsets.end() - 1);
      forEachEdge([&](CandidateIndex, int, VertexIndex low, VertexIndex high) {
        neighbours[cursor[low]++] = high;
      });
    }
    std::vector<std::uint32_t> &unique_offsets = scaffold_.edge_vertex_offsets;
    unique_offsets.assign(n + 1, 0);
    std::size_t write = 0;
    for (std::size_t a = 0; a < n; ++a) {
      auto begin = neighbours.begin() + offsets[a], end = neighbours.begin() + offsets[a + 1];
      std::sort(begin, end);
      const auto unique_end = std::unique(begin, end);
      unique_offsets[a] = static_cast<std::uint32_t>(write);
      for (auto it = begin; it != unique_end; ++it)
        neighbours[write++] = *it;
    }
    unique_offsets[n] = static_cast<std::uint32_t>(write);
    neighbours.resize(write);
    neighbours.shrink_to_fit();
    const std::size_t edge_count = write;

    // The dictionary is complete now: every edge of the graph is found.
    scaffold_.edge_offsets.assign(edge_count + 1, 0);
    forEachEdge([&](CandidateIndex t, int k, VertexIndex low, VertexIndex high) {
      const EdgeIndex e = scaffold_.findEdge(low, high);
      candidates[t].edges[k] = e;
      ++scaffold_.edge_offsets[e + 1];
    });
    std::partial_sum(scaffold_.edge_offsets.begin(), scaffold_.edge_offsets.end(),
                     scaffold_.edge_offsets.begin());
    scaffold_.edge_candidates.resize(scaffold_.edge_offsets.back());
    std::vector<std::uint32_t> cursor(scaffold_.edge_offsets.begin(),
                                      scaffold_.edge_offsets.end() - 1);
    for (CandidateIndex t = 0; t < candidates.size(); ++t)
      if (in_graph[t])
        for (EdgeIndex e : candidates[t].edges)
          scaffold_.edge_candidates[cursor[e]++] = t;
  }

  const std::vector<Eigen::Vector3d> &points_;
  const ScaffoldOptions &options_;
  MedialScaffold scaffold_;
  /// Per chunk of cells, its facets as the facet pass found them, for the
  /// candidates' pass, and its Gabriel triangles, for the local scales.
  std::vector<ChunkFacets> chunk_facets_;
  std::vector<std::vector<GabrielTriangle>> chunk_triangles_;
};

} // namespace

MedialScaffold buildMedialScaffold(const std::vector<Eigen::Vector3d> &points,
                                   const ScaffoldOptions &options) {
  return ScaffoldBuilder(points, options).build();
}

} // namespace pcl_ms
