// SPDX-License-Identifier: GPL-3.0-or-later
// The medial axis left by the surface: poles of the Voronoi diagram as A1^4
// nodes, the Voronoi edges between them as A1^3 curves, and each node's side
// of the closed components (docs/algorithm.md, "Medial axis output").
#include <pcl_ms/medial_axis.h>
#include <pcl_ms/reconstruct.h>

#include "indexed_delaunay.h"
#include "sort_unique.h"

#include <CGAL/constructions/kernel_ftC3.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <string>
#include <tuple>

namespace pcl_ms {
namespace {

using detail::CellHandle;
using detail::Delaunay;
using detail::Kernel;
using detail::KernelPoint;
using detail::VertexHandle;

constexpr std::uint32_t no_cell = std::numeric_limits<std::uint32_t>::max();

// A pole is a node only when two of its ball's contact points (the
// tetrahedron's corners) are at least this angle apart as seen from its
// centre (the theta filter of Foskey, Lin and Manocha's simplified medial
// axis). Balls whose four contacts crowd into a small cap of the surface are
// flat tetrahedra hugging it: nearly on one circle, so the sample hardly
// fixes where along the surface normal their centre lies (on a sampled unit
// sphere such poles were up to 0.07 off the centre with 5,000 points and 0.37
// with 20,000; the wide ones less than 1e-6).
// At 45 degrees the sheets that run into an edge are kept where its two faces
// meet at up to 135 degrees.
constexpr double min_contact_angle = M_PI / 4;

bool lessPoint(const Eigen::Vector3d &a, const Eigen::Vector3d &b) {
  return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
}

Eigen::Vector3d toEigen(const KernelPoint &p) { return {p.x(), p.y(), p.z()}; }

/// A triangle's corners in ascending order: the key of a Delaunay facet.
Triangle sortedTriangle(VertexIndex a, VertexIndex b, VertexIndex c) {
  Triangle triangle{a, b, c};
  std::sort(triangle.begin(), triangle.end());
  return triangle;
}

/// Per finite cell: its circumcentre and radius, computed from the corners
/// in coordinate order so that the figures do not depend on how CGAL
/// happens to order them (that follows the insertion order).
struct CellBall {
  std::array<VertexIndex, 4> corners; // ascending by coordinates
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0;
  bool valid = false; // false: no circumcentre in double (a flat cell)
  /// Whether two corners subtend at least min_contact_angle at the centre.
  bool wide = false;
};

/// What the surface says about each point and Delaunay facet.
struct SurfaceFacets {
  /// Per cell, bit i set when its facet i (opposite corner i) is a surface
  /// triangle; and when that triangle is a wall: part of a closed component
  /// whose triangles are all Delaunay facets, which separates inside from
  /// outside.
  std::vector<std::uint8_t> in_surface, wall;
  /// The walls once each, as (cell, facet): both sides of a wall reached
  /// from outside means the flood leaked past a closed component.
  std::vector<std::pair<std::uint32_t, int>> wall_facets;
  /// The first surface_walls of them are surface triangles, the rest plugs;
  /// the component of each of those surface triangles.
  std::size_t surface_walls = 0;
  std::vector<std::uint32_t> wall_component; // a triangle's index stands for its component
  std::size_t triangles = 0;
  /// Points on a component with a boundary (or one that cannot serve as a
  /// wall): cells touching them get no side.
  std::vector<bool> on_open_part;
};

class MedialAxisBuilder {
public:
  explicit MedialAxisBuilder(const std::vector<Eigen::Vector3d> &points) : points_(points) {}

  MedialAxis build(const std::vector<Triangle> &surface) {
    MedialAxis axis;
    findDistinctPoints();
    if (distinct_.size() < 4)
      return axis;
    triangulate();
    if (delaunay_.dimension() < 3)
      return axis;
    collectCells();
    const SurfaceFacets facets = classifySurface(surface);
    const std::vector<std::uint8_t> side = cellSides(facets);
    const std::vector<bool> is_pole = findPoles();

    // Nodes in the order of their corners' coordinates.
    std::vector<std::uint32_t> pole_cells;
    for (std::uint32_t c = 0; c < cells_.size(); ++c)
      if (is_pole[c] && balls_[c].wide)
        pole_cells.push_back(c);
    std::sort(pole_cells.begin(), pole_cells.end(), [&](std::uint32_t a, std::uint32_t b) {
      return std::lexicographical_compare(
          balls_[a].corners.begin(), balls_[a].corners.end(), balls_[b].corners.begin(),
          balls_[b].corners.end(),
          [&](VertexIndex p, VertexIndex q) { return rank_[p] < rank_[q]; });
    });
    std::vector<std::uint32_t> node_of_cell(cells_.size(), no_cell);
    for (std::uint32_t n = 0; n < pole_cells.size(); ++n) {
      const CellBall &ball = balls_[pole_cells[n]];
      node_of_cell[pole_cells[n]] = n;
      axis.node_positions.push_back(ball.centre);
      axis.node_radii.push_back(ball.radius);
      axis.node_side.push_back(side[pole_cells[n]]);
    }

    // Curves: Voronoi edges between two nodes across a facet the surface
    // did not take.
    for (std::uint32_t c = 0; c < cells_.size(); ++c) {
      if (node_of_cell[c] == no_cell)
        continue;
      for (int i = 0; i < 4; ++i) {
        const CellHandle neighbour = cells_[c]->neighbor(i);
        if (delaunay_.is_infinite(neighbour))
          continue;
        const std::uint32_t other = neighbour->info();
        if (other < c || node_of_cell[other] == no_cell)
          continue; // each facet once, from its lower-numbered cell
        if (facets.in_surface[c] & (1u << i))
          continue;
        const std::uint32_t a = node_of_cell[c], b = node_of_cell[other];
        axis.curves.push_back({std::min(a, b), std::max(a, b)});
      }
    }
    std::sort(axis.curves.begin(), axis.curves.end());
    return axis;
  }

private:
  /// Exact duplicates stand for the first of them in coordinate order.
  void findDistinctPoints() {
    std::vector<VertexIndex> order(points_.size());
    std::iota(order.begin(), order.end(), VertexIndex(0));
    std::sort(order.begin(), order.end(), [&](VertexIndex a, VertexIndex b) {
      return lessPoint(points_[a], points_[b]) || (!lessPoint(points_[b], points_[a]) && a < b);
    });
    representative_.assign(points_.size(), 0);
    rank_.assign(points_.size(), 0);
    for (std::size_t k = 0; k < order.size(); ++k) {
      if (k > 0 && points_[order[k]] == points_[order[k - 1]]) {
        representative_[order[k]] = representative_[order[k - 1]];
        continue;
      }
      representative_[order[k]] = order[k];
      rank_[order[k]] = static_cast<VertexIndex>(distinct_.size());
      distinct_.push_back(order[k]);
    }
  }

  void triangulate() {
    std::vector<detail::IndexedPoint> input = detail::indexedPoints(points_, distinct_);
    // The points go in in coordinate order and CGAL's symbolic perturbation
    // is by coordinates too: the same point set gives the same tetrahedra.
    detail::insertIndexed(delaunay_, input);
    vertex_of_point_.assign(points_.size(), VertexHandle());
    for (VertexHandle vertex : delaunay_.finite_vertex_handles())
      vertex_of_point_[vertex->info()] = vertex;
  }

  void collectCells() {
    std::uint32_t id = 0;
    for (CellHandle cell : delaunay_.all_cell_handles()) {
      cell->info() = id++;
      cells_.push_back(cell);
    }
    balls_.resize(cells_.size());
    for (std::uint32_t c = 0; c < cells_.size(); ++c) {
      const CellHandle cell = cells_[c];
      if (delaunay_.is_infinite(cell))
        continue;
      CellBall &ball = balls_[c];
      for (int k = 0; k < 4; ++k)
        ball.corners[k] = cell->vertex(k)->info();
      std::sort(ball.corners.begin(), ball.corners.end(),
                [&](VertexIndex p, VertexIndex q) { return rank_[p] < rank_[q]; });
      // CGAL's circumcentre construction (circumcenterC3), but with a flat
      // cell's zero volume checked instead of asserted (as in flat_cells.h).
      const Eigen::Vector3d &p = points_[ball.corners[0]], &q = points_[ball.corners[1]],
                            &r = points_[ball.corners[2]], &t = points_[ball.corners[3]];
      double num_x, num_y, num_z, den;
      CGAL::determinants_for_circumcenterC3(p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), r.x(), r.y(),
                                            r.z(), t.x(), t.y(), t.z(), num_x, num_y, num_z, den);
      if (den == 0)
        continue;
      ball.centre = p + Eigen::Vector3d(num_x, -num_y, num_z) / (2 * den);
      ball.radius = (ball.centre - p).norm();
      double longest = 0;
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b)
          longest = std::max(longest, (points_[ball.corners[a]] - points_[ball.corners[b]]).norm());
      ball.valid = std::isfinite(ball.radius);
      ball.wide = longest >= 2 * ball.radius * std::sin(min_contact_angle / 2);
    }
  }

  /// Surface triangles in distinct points; which components are closed (no
  /// edge used once) and so can wall off an inside.
  SurfaceFacets classifySurface(const std::vector<Triangle> &surface) const {
    SurfaceFacets facets;
    facets.on_open_part.assign(points_.size(), false);
    std::vector<Triangle> triangles;
    triangles.reserve(surface.size());
    for (const Triangle &t : surface) {
      const Triangle key =
          sortedTriangle(representative_[t[0]], representative_[t[1]], representative_[t[2]]);
      if (key[0] != key[1] && key[1] != key[2])
        triangles.push_back(key);
    }
    detail::sortUnique(triangles);

    // Components by shared edges (union-find over triangles).
    std::vector<std::uint32_t> parent(triangles.size());
    std::iota(parent.begin(), parent.end(), 0u);
    const auto root = [&](std::uint32_t t) {
      while (parent[t] != t)
        t = parent[t] = parent[parent[t]];
      return t;
    };
    struct EdgeUse {
      VertexIndex a, b;
      std::uint32_t triangle;
      bool operator<(const EdgeUse &other) const {
        return std::tie(a, b, triangle) < std::tie(other.a, other.b, other.triangle);
      }
    };
    std::vector<EdgeUse> edges;
    edges.reserve(3 * triangles.size());
    for (std::uint32_t t = 0; t < triangles.size(); ++t) {
      const Triangle &k = triangles[t];
      edges.push_back({k[0], k[1], t});
      edges.push_back({k[1], k[2], t});
      edges.push_back({k[0], k[2], t});
    }
    std::sort(edges.begin(), edges.end());
    std::vector<bool> touches_boundary(triangles.size(), false);
    for (std::size_t first = 0; first < edges.size();) {
      std::size_t last = first + 1;
      while (last < edges.size() && edges[last].a == edges[first].a &&
             edges[last].b == edges[first].b)
        ++last;
      if (last - first == 1)
        touches_boundary[edges[first].triangle] = true;
      for (std::size_t e = first + 1; e < last; ++e)
        parent[root(edges[e].triangle)] = root(edges[first].triangle);
      first = last;
    }
    // The triangles by their first corner (they are sorted), so that one
    // sweep over the cells' facets finds them.
    std::vector<std::uint32_t> first_of(points_.size() + 1, 0);
    for (const Triangle &k : triangles)
      ++first_of[k[0] + 1];
    std::partial_sum(first_of.begin(), first_of.end(), first_of.begin());
    std::vector<bool> is_facet(triangles.size(), false);
    facets.in_surface.assign(cells_.size(), 0);
    facets.wall.assign(cells_.size(), 0);
    std::vector<std::pair<std::uint32_t, int>> found; // (cell, facet) per surface triangle
    std::vector<std::uint32_t> found_triangle;
    for (std::uint32_t c = 0; c < cells_.size(); ++c) {
      for (int i = 0; i < 4; ++i) {
        if (delaunay_.is_infinite(cells_[c], i))
          continue;
        const Triangle key = sortedTriangle(cells_[c]->vertex((i + 1) & 3)->info(),
                                            cells_[c]->vertex((i + 2) & 3)->info(),
                                            cells_[c]->vertex((i + 3) & 3)->info());
        for (std::uint32_t t = first_of[key[0]]; t < first_of[key[0] + 1]; ++t)
          if (triangles[t] == key) {
            facets.in_surface[c] |= std::uint8_t(1u << i);
            if (!is_facet[t]) { // once per facet, from the first cell met
              found.emplace_back(c, i);
              found_triangle.push_back(t);
            }
            is_facet[t] = true;
            break;
          }
      }
    }
    // Only closed components, those without a boundary edge, can wall off
    // an inside.
    std::vector<bool> open_component(triangles.size(), false);
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      if (touches_boundary[t])
        open_component[root(t)] = true;
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      if (open_component[root(t)])
        for (VertexIndex v : triangles[t])
          facets.on_open_part[v] = true;
    for (std::size_t h = 0; h < found.size(); ++h)
      if (!open_component[root(found_triangle[h])]) {
        addWall(found[h].first, found[h].second, facets);
        facets.wall_component.push_back(root(found_triangle[h]));
      }
    facets.triangles = triangles.size();
    // Only these separate the inside from the outside; the plugs below may
    // lie on either side.
    facets.surface_walls = facets.wall_facets.size();
    // A surface triangle that is no Delaunay facet (a swapped diagonal, a
    // hole filled across other triangles) leaves a gap in the walls: the
    // Delaunay facets among its corners and those of its neighbours across
    // its edges close it (for a swapped pair, the other diagonal's two).
    for (std::uint32_t t = 0; t < triangles.size(); ++t) {
      if (is_facet[t] || open_component[root(t)])
        continue;
      std::vector<VertexIndex> around(triangles[t].begin(), triangles[t].end());
      for (int e = 0; e < 3; ++e) {
        const VertexIndex a = triangles[t][e == 2 ? 1 : 0], b = triangles[t][e == 0 ? 1 : 2];
        auto use = std::lower_bound(edges.begin(), edges.end(), EdgeUse{a, b, 0});
        for (; use != edges.end() && use->a == a && use->b == b; ++use)
          around.insert(around.end(), triangles[use->triangle].begin(),
                        triangles[use->triangle].end());
      }
      detail::sortUnique(around);
      for (std::size_t i = 0; i < around.size(); ++i)
        for (std::size_t j = i + 1; j < around.size(); ++j)
          for (std::size_t k = j + 1; k < around.size(); ++k) {
            CellHandle cell;
            int ci = 0, cj = 0, ck = 0;
            if (delaunay_.is_facet(vertex_of_point_[around[i]], vertex_of_point_[around[j]],
                                   vertex_of_point_[around[k]], cell, ci, cj, ck))
              addWall(cell->info(), 6 - ci - cj - ck, facets);
          }
    }
    return facets;
  }

  /// Makes facet `i` of cell `c` a wall, seen from both its cells.
  void addWall(std::uint32_t c, int i, SurfaceFacets &facets) const {
    if (facets.wall[c] & (1u << i))
      return;
    const CellHandle neighbour = cells_[c]->neighbor(i);
    facets.wall[c] |= std::uint8_t(1u << i);
    facets.wall[neighbour->info()] |= std::uint8_t(1u << neighbour->index(cells_[c]));
    facets.wall_facets.emplace_back(c, i);
  }

  /// Flood from the infinite cells across every facet that is not a wall:
  /// cells it cannot reach are inside a closed component.
  std::vector<std::uint8_t> cellSides(const SurfaceFacets &facets) const {
    std::vector<bool> reached(cells_.size(), false);
    std::deque<std::uint32_t> queue;
    for (std::uint32_t c = 0; c < cells_.size(); ++c)
      if (delaunay_.is_infinite(cells_[c])) {
        reached[c] = true;
        queue.push_back(c);
      }
    while (!queue.empty()) {
      const std::uint32_t c = queue.front();
      queue.pop_front();
      for (int i = 0; i < 4; ++i) {
        const std::uint32_t next = cells_[c]->neighbor(i)->info();
        if (reached[next])
          continue;
        if (facets.wall[c] & (1u << i))
          continue;
        reached[next] = true;
        queue.push_back(next);
      }
    }
    // A closed component that the flood got past (its walls did not close
    // it off after all) has its inside among the reached cells: most of its
    // triangles are then reached on both sides (a few can be where the
    // surface folds close to a plugged gap: a small pocket, not a leak).
    // The reached cells can then no longer be told apart: no side.
    std::vector<std::size_t> walls_of(facets.triangles, 0), leaking_walls_of(facets.triangles, 0);
    for (std::size_t w = 0; w < facets.surface_walls; ++w) {
      const auto [c, i] = facets.wall_facets[w];
      ++walls_of[facets.wall_component[w]];
      if (reached[c] && reached[cells_[c]->neighbor(i)->info()])
        ++leaking_walls_of[facets.wall_component[w]];
    }
    bool leaked = false;
    for (std::size_t component = 0; component < walls_of.size(); ++component)
      leaked = leaked || 2 * leaking_walls_of[component] > walls_of[component];
    std::vector<std::uint8_t> side(cells_.size(), MedialAxis::outside);
    for (std::uint32_t c = 0; c < cells_.size(); ++c) {
      if (!reached[c]) {
        side[c] = MedialAxis::inside;
        continue;
      }
      if (leaked) {
        side[c] = MedialAxis::open;
        continue;
      }
      for (int k = 0; k < 4; ++k) {
        const VertexHandle corner = cells_[c]->vertex(k);
        if (!delaunay_.is_infinite(corner) && facets.on_open_part[corner->info()])
          side[c] = MedialAxis::open;
      }
    }
    return side;
  }

  /// Per point its poles (Amenta, Choi and Kolluri's power crust): the
  /// farthest Voronoi vertex of its cell, and the farthest on the other
  /// side of the point. A point on the convex hull has an unbounded cell:
  /// its first pole is at infinity, in the direction of its hull facets'
  /// outward normals, and is not a node. Two sweeps over the cells, each
  /// visiting every corner, instead of a walk around every point.
  std::vector<bool> findPoles() const {
    // Farther wins; equal radii go to the cell with the smaller corners.
    const auto farther = [&](std::uint32_t a, std::uint32_t b) {
      if (balls_[a].radius != balls_[b].radius)
        return balls_[a].radius > balls_[b].radius;
      return std::lexicographical_compare(
          balls_[a].corners.begin(), balls_[a].corners.end(), balls_[b].corners.begin(),
          balls_[b].corners.end(),
          [&](VertexIndex p, VertexIndex q) { return rank_[p] < rank_[q]; });
    };
    std::vector<std::uint32_t> first(points_.size(), no_cell), second(points_.size(), no_cell);
    std::vector<Eigen::Vector3d> outward(points_.size(), Eigen::Vector3d::Zero());
    std::vector<bool> on_hull(points_.size(), false);
    for (std::uint32_t c = 0; c < cells_.size(); ++c) {
      const CellHandle cell = cells_[c];
      if (delaunay_.is_infinite(cell)) {
        // The hull facet is the one opposite the infinite vertex; its
        // normal points away from the finite cell behind it.
        const int at_infinity = cell->index(delaunay_.infinite_vertex());
        const VertexHandle corners[3] = {cell->vertex((at_infinity + 1) & 3),
                                         cell->vertex((at_infinity + 2) & 3),
                                         cell->vertex((at_infinity + 3) & 3)};
        const Eigen::Vector3d a = toEigen(corners[0]->point()), b = toEigen(corners[1]->point()),
                              d = toEigen(corners[2]->point());
        Eigen::Vector3d normal = (b - a).cross(d - a);
        const CellHandle behind = cell->neighbor(at_infinity);
        if (normal.dot(toEigen(behind->vertex(behind->index(cell))->point()) - a) > 0)
          normal = -normal;
        const double length = normal.norm();
        for (const VertexHandle &corner : corners) {
          on_hull[corner->info()] = true;
          if (length > 0)
            outward[corner->info()] += normal / length;
        }
        continue;
      }
      if (!balls_[c].valid)
        continue;
      for (VertexIndex p : balls_[c].corners)
        if (first[p] == no_cell || farther(c, first[p]))
          first[p] = c;
    }
    std::vector<bool> is_pole(cells_.size(), false);
    for (VertexIndex p : distinct_) {
      if (first[p] == no_cell)
        continue;
      if (!on_hull[p]) {
        is_pole[first[p]] = true;
        outward[p] = balls_[first[p]].centre - points_[p];
      }
    }
    for (std::uint32_t c = 0; c < cells_.size(); ++c) {
      if (!balls_[c].valid)
        continue;
      for (VertexIndex p : balls_[c].corners)
        if ((balls_[c].centre - points_[p]).dot(outward[p]) < 0 &&
            (second[p] == no_cell || farther(c, second[p])))
          second[p] = c;
    }
    for (VertexIndex p : distinct_)
      if (second[p] != no_cell)
        is_pole[second[p]] = true;
    return is_pole;
  }

  const std::vector<Eigen::Vector3d> &points_;
  std::vector<VertexIndex> representative_;
  std::vector<VertexIndex> distinct_; // in coordinate order
  /// A distinct point's place in that order: comparing ranks compares the
  /// points by coordinates.
  std::vector<VertexIndex> rank_;
  Delaunay delaunay_;
  std::vector<VertexHandle> vertex_of_point_;
  std::vector<CellHandle> cells_;
  std::vector<CellBall> balls_;
};

} // namespace

MedialAxis computeMedialAxis(const std::vector<Eigen::Vector3d> &points,
                             const std::vector<Triangle> &surface) {
  if (points.size() >= std::numeric_limits<VertexIndex>::max())
    throw ReconstructionError("too many points for 32-bit indices");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw ReconstructionError("medial axis: point " + std::to_string(i) +
                                " has a NaN or infinite coordinate");
  for (std::size_t t = 0; t < surface.size(); ++t)
    for (VertexIndex v : surface[t])
      if (v >= points.size())
        throw ReconstructionError("medial axis: triangle " + std::to_string(t) + " uses point " +
                                  std::to_string(v) + " of " + std::to_string(points.size()));
  return MedialAxisBuilder(points).build(surface);
}

} // namespace pcl_ms
