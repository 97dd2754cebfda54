// SPDX-License-Identifier: GPL-3.0-or-later
// Unit tests of each core stage on configurations whose answers are known by hand.
#include "core_test_support.h"
#include "fan_choice.h"
#include "finish_steps.h"
#include "flat_cells.h"
#include "threads.h"

#include <pcl_ms/costs.h>
#include <pcl_ms/finish.h>
#include <pcl_ms/greedy.h>
#include <pcl_ms/mesh_topology.h>
#include <pcl_ms/scaffold.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <array>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <utility>

using namespace pcl_ms;
using pcl_ms_test::expectCleanManifold;
using pcl_ms_test::moebiusBand;

namespace {

std::vector<Eigen::Vector3d> regularTetrahedron() {
  // Edge length 1.
  return {{0, 0, 0},
          {1, 0, 0},
          {0.5, std::sqrt(3.0) / 2, 0},
          {0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3.0)}};
}

std::vector<Eigen::Vector3d> cubeCorners() {
  std::vector<Eigen::Vector3d> corners;
  for (int i = 0; i < 8; ++i)
    corners.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  return corners;
}

const Candidate *findCandidate(const MedialScaffold &scaffold, Triangle vertices) {
  std::sort(vertices.begin(), vertices.end());
  for (const Candidate &candidate : scaffold.candidates)
    if (candidate.vertices == vertices)
      return &candidate;
  return nullptr;
}

Result runOn(const std::vector<Eigen::Vector3d> &points, Parameters parameters = {}) {
  std::vector<float> xyz;
  for (const auto &p : points)
    xyz.insert(xyz.end(), {float(p.x()), float(p.y()), float(p.z())});
  return reconstruct(pcl_ms_test::viewOf(xyz), parameters);
}

} // namespace

// ---- costs ------------------------------------------------------------------

TEST(Costs, CompactnessOfKnownTriangles) {
  EXPECT_NEAR(triangleShape({0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}).compactness, 1.0,
              1e-12);
  // Right isosceles: A = 1/2, sum of squared sides = 4.
  EXPECT_NEAR(triangleShape({0, 0, 0}, {1, 0, 0}, {0, 1, 0}).compactness, std::sqrt(3.0) / 2,
              1e-12);
  const TriangleShape flat = triangleShape({0, 0, 0}, {1, 0, 0}, {2, 0, 0});
  EXPECT_EQ(flat.area, 0.0);
  EXPECT_EQ(flat.compactness, 0.0);
  EXPECT_DOUBLE_EQ(flat.perimeter, 4.0);
  EXPECT_DOUBLE_EQ(flat.longest_side, 2.0);
}

TEST(Costs, BendingAngleAcrossSharedEdge) {
  const Eigen::Vector3d p(0, 0, 0), q(1, 0, 0), t(0.3, 1, 0);
  EXPECT_NEAR(bendingAngle(p, q, t, {0.7, -2, 0}), 0.0, 1e-12);     // flat continuation
  EXPECT_NEAR(bendingAngle(p, q, t, {0.1, 0.5, 0}), M_PI, 1e-12);   // folded back
  EXPECT_NEAR(bendingAngle(p, q, t, {0.5, 0, 3}), M_PI / 2, 1e-12); // right angle
  // One edge object asked about several triangles in turn (the greedy's
  // context): each angle is the one its position across the edge gives,
  // whatever was asked before. Across this edge, t lies along +y; s at
  // (.., 0.2, 0.9) is turned atan2(0.9, 0.2) away from t's side.
  const BendingAcrossEdge edge(p, q, t);
  EXPECT_NEAR(edge.angleTo({0.7, -2, 0}), 0.0, 1e-12);
  EXPECT_NEAR(edge.angleTo({0.5, 0, 3}), M_PI / 2, 1e-12);
  EXPECT_NEAR(edge.angleTo({-4, 0.2, 0.9}), M_PI - std::atan2(0.9, 0.2), 1e-12);
  EXPECT_NEAR(edge.angleTo({0.7, -2, 0}), 0.0, 1e-12);
  // An edge whose ends coincide bends by pi whatever the triangles.
  const BendingAcrossEdge degenerate(p, p, t);
  EXPECT_TRUE(degenerate.degenerate());
  EXPECT_EQ(degenerate.angleTo({0.5, 0, 3}), M_PI);
  EXPECT_FALSE(bendsSurelyLessThan(p, p, t, {0.7, -2, 0}, 1.0));
}

// The twist repair tells flat edges without the arctangent where it can:
// wherever it says "surely below", bendingAngle() must be below, right up
// to the limit; and it must say so for most edges well inside it. Random
// edges and apexes, including bendings within 1e-9 of the limit and
// coinciding edge ends.
TEST(Costs, SurelyLessBendingAgreesWithTheAngle) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double limit = 0.5, limit_tan_squared = std::tan(limit) * std::tan(limit);
  std::size_t sure = 0, well_inside = 0;
  for (int i = 0; i < 200000; ++i) {
    const Eigen::Vector3d p(unit(random), unit(random), unit(random));
    const Eigen::Vector3d q =
        i % 1000 == 0
            ? p
            : Eigen::Vector3d(p + Eigen::Vector3d(unit(random), unit(random), unit(random)));
    const Eigen::Vector3d axis = (q - p).normalized();
    Eigen::Vector3d across = axis.unitOrthogonal();
    const Eigen::Vector3d up = axis.cross(across);
    const double along_t = unit(random), along_s = unit(random);
    const double wanted = i % 3 == 0 ? limit + 1e-9 * unit(random) : 1.5 * (unit(random) + 1);
    const Eigen::Vector3d t = p + along_t * (q - p) + across;
    const Eigen::Vector3d s =
        p + along_s * (q - p) - std::cos(wanted) * across + std::sin(wanted) * up;
    const bool surely = bendsSurelyLessThan(p, q, t, s, limit_tan_squared);
    const double bending = bendingAngle(p, q, t, s);
    if (surely) {
      ++sure;
      ASSERT_LT(bending, limit) << i;
    }
    if (q != p && bending < 0.99 * limit) {
      ++well_inside;
      EXPECT_TRUE(surely) << i << " bending " << bending;
    }
  }
  EXPECT_GT(sure, 10000u);
  EXPECT_GT(well_inside, 10000u);
}

TEST(Costs, BendingPenaltyMatchesPaper) {
  EXPECT_DOUBLE_EQ(bendingPenalty(0.0), -1.0);
  // The paper: f is about 0 at 40 degrees (exactly at ln 2, 39.7 degrees)
  // and about 8.24 at 80 degrees.
  EXPECT_NEAR(bendingPenalty(std::log(2.0)), 0.0, 1e-12);
  EXPECT_NEAR(bendingPenalty(40.0 * M_PI / 180), 0.0, 0.03);
  EXPECT_NEAR(bendingPenalty(80.0 * M_PI / 180), 8.24, 0.01);
  // Three flat neighbours cancel the base cost (Eq. 1 vs Eq. 2).
  const double inverse = 1.0 / (0.5 * 0.9 * 0.9);
  const double base = baseCost(3.0, 0.5, 0.9);
  EXPECT_NEAR(base + 3 * contextCost(1.0, inverse, 0.0), 0.0, 1e-12);
}

// ---- scaffold -----------------------------------------------------------------

TEST(Scaffold, RegularTetrahedronHasFourAcuteCandidates) {
  const MedialScaffold scaffold = buildMedialScaffold(regularTetrahedron(), {});
  ASSERT_EQ(scaffold.candidates.size(), 4u);
  EXPECT_EQ(scaffold.type1, 4u);
  EXPECT_EQ(scaffold.type2 + scaffold.type3 + scaffold.oversize, 0u);
  EXPECT_FALSE(scaffold.planar);
  EXPECT_NEAR(scaffold.d_med, 1.0 / std::sqrt(3.0), 1e-6); // face circumradius
  EXPECT_NEAR(scaffold.d_max, Parameters().rho / std::sqrt(3.0), 1e-5);
  // Hull facets: the finite piece of the Voronoi ray runs from the face's
  // circumcentre to the tetrahedron's, i.e. the inradius 1 / (2 sqrt 6).
  const double inradius = 1.0 / (2.0 * std::sqrt(6.0));
  for (const Candidate &candidate : scaffold.candidates) {
    EXPECT_EQ(candidate.type, CandidateType::acute);
    EXPECT_NEAR(candidate.base_cost, 3.0 / inradius, 1e-4);
    EXPECT_NEAR(candidate.inverse_shock_compactness, 1.0 / inradius, 1e-4);
  }
  // Six edges, each shared by two faces.
  ASSERT_EQ(scaffold.numberOfEdges(), 6u);
  for (EdgeIndex e = 0; e < 6; ++e)
    EXPECT_EQ(scaffold.edgeEnd(e) - scaffold.edgeBegin(e), 2);
}

TEST(Scaffold, EdgeGraphHoldsOnlyTheCandidatesOfPassOne) {
  std::vector<Eigen::Vector3d> points = pcl_ms_test::bunnyReference().vertices;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d &p : points)
    centre += p / static_cast<double>(points.size());
  for (Eigen::Vector3d &p : points)
    p -= centre;
  MedialScaffold scaffold = buildMedialScaffold(points, {});
  ASSERT_GT(scaffold.type3, 0u);
  std::size_t in_graph = 0, edges_of_type_three_only = 0;
  for (CandidateIndex t = 0; t < scaffold.candidates.size(); ++t) {
    const Candidate &candidate = scaffold.candidates[t];
    for (int k = 0; k < 3; ++k) {
      const EdgeIndex e = candidate.edges[k];
      const EdgeIndex found =
          scaffold.findEdge(candidate.vertices[(k + 1) % 3], candidate.vertices[k]);
      if (candidate.type == CandidateType::ambiguous) {
        ASSERT_EQ(e, no_edge);
        edges_of_type_three_only += found == no_edge;
        continue;
      }
      ASSERT_EQ(e, found);
      ASSERT_TRUE(std::binary_search(scaffold.edgeBegin(e), scaffold.edgeEnd(e), t));
    }
    in_graph += candidate.type != CandidateType::ambiguous;
  }
  EXPECT_EQ(scaffold.edge_candidates.size(), 3 * in_graph);
  EXPECT_GT(edges_of_type_three_only, 0u);

  // Pass 2 numbers the edges of the type III candidates it meshes, new
  // edges included, and the mesh stays edge-manifold.
  std::set<Triangle> type_three;
  for (const Candidate &candidate : scaffold.candidates)
    if (candidate.type == CandidateType::ambiguous)
      type_three.insert(candidate.vertices);
  GreedyMesher mesher(std::move(scaffold), points, Parameters());
  mesher.run();
  std::map<std::pair<VertexIndex, VertexIndex>, int> edge_uses;
  std::size_t meshed_type_three = 0;
  for (Triangle triangle : mesher.triangles()) {
    std::sort(triangle.begin(), triangle.end());
    meshed_type_three += type_three.count(triangle);
    for (int k = 0; k < 3; ++k)
      ++edge_uses[std::minmax(triangle[k], triangle[(k + 1) % 3])];
  }
  EXPECT_GT(meshed_type_three, 0u);
  for (const auto &[edge, uses] : edge_uses)
    ASSERT_LE(uses, 2) << edge.first << "-" << edge.second;
}

// Types I and II come first, in the order of their corners (what keeps
// neighbours on the surface close in memory), type III after them, in the
// order of their corners too. The list is the same for any thread count:
// on two threads CGAL's parallel insertion builds the triangulation, whose
// cells and their corners are stored in another order, and several threads
// take the slots at once.
TEST(Scaffold, CandidatesComeInTheirCornersOrderFromEitherTriangulation) {
  const std::vector<Eigen::Vector3d> points = pcl_ms_test::bunnyReference().vertices;
  ScaffoldOptions one_thread, two_threads;
  two_threads.num_threads = 2;
  const MedialScaffold scaffold = buildMedialScaffold(points, one_thread);
  EXPECT_FALSE(scaffold.parallel_triangulation);
  const std::vector<Candidate> &candidates = scaffold.candidates;
  const std::size_t gabriel = scaffold.type1 + scaffold.type2;
  ASSERT_GT(gabriel, 10000u);
  ASSERT_GT(scaffold.type3, 10000u);
  ASSERT_EQ(candidates.size(), gabriel + scaffold.type3);
  for (std::size_t t = 0; t < candidates.size(); ++t)
    ASSERT_EQ(candidates[t].type == CandidateType::ambiguous, t >= gabriel) << t;
  for (std::size_t t = 1; t < candidates.size(); ++t) {
    if (t == gabriel) // each group ascends on its own
      continue;
    ASSERT_LT(candidates[t - 1].vertices, candidates[t].vertices) << t;
  }

  const MedialScaffold again = buildMedialScaffold(points, two_threads);
  EXPECT_TRUE(again.parallel_triangulation);
  ASSERT_EQ(again.candidates.size(), candidates.size());
  for (std::size_t t = 0; t < candidates.size(); ++t) {
    ASSERT_EQ(again.candidates[t].vertices, candidates[t].vertices) << t;
    ASSERT_EQ(again.candidates[t].type, candidates[t].type) << t;
    ASSERT_EQ(again.candidates[t].base_cost, candidates[t].base_cost) << t;
    ASSERT_EQ(again.candidates[t].inverse_shock_compactness,
              candidates[t].inverse_shock_compactness)
        << t;
    ASSERT_EQ(again.candidates[t].edges, candidates[t].edges) << t;
  }
  EXPECT_EQ(again.local_scale, scaffold.local_scale);
  EXPECT_EQ(again.d_med, scaffold.d_med);
  EXPECT_EQ(again.oversize, scaffold.oversize);
  EXPECT_EQ(again.degenerate, scaffold.degenerate);
}

namespace {

/// Just what detail::circumcentre reads of a triangulation's cell: its
/// corners' points and indices, here in any order.
struct CornerStub {
  CGAL::Epick::Point_3 position;
  std::uint32_t index;
  const CGAL::Epick::Point_3 &point() const { return position; }
  std::uint32_t info() const { return index; }
};
struct CellStub {
  std::array<const CornerStub *, 4> corners;
  const CornerStub *vertex(int k) const { return corners[static_cast<std::size_t>(k)]; }
};

} // namespace

// A Voronoi vertex (the shock lengths' ends) comes out bit for bit the same
// whatever order a cell stores its corners in: the two triangulations
// store them differently.
TEST(Scaffold, CircumcentreDoesNotDependOnTheCornersOrder) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  int orders_that_moved_the_plain_formula = 0;
  for (int cell = 0; cell < 200; ++cell) {
    std::array<CornerStub, 4> corners;
    for (std::uint32_t k = 0; k < 4; ++k)
      corners[k] = {{coordinate(random), coordinate(random), coordinate(random)}, 10 * k + 3};
    std::array<int, 4> order = {0, 1, 2, 3};
    CellStub stub{{&corners[0], &corners[1], &corners[2], &corners[3]}};
    double first[3];
    ASSERT_TRUE(detail::circumcentre(&stub, first));
    const CGAL::Epick::Point_3 plain = CGAL::circumcenter(corners[0].position, corners[1].position,
                                                          corners[2].position, corners[3].position);
    while (std::next_permutation(order.begin(), order.end())) {
      for (int k = 0; k < 4; ++k)
        stub.corners[static_cast<std::size_t>(k)] = &corners[static_cast<std::size_t>(order[k])];
      double centre[3];
      ASSERT_TRUE(detail::circumcentre(&stub, centre));
      for (int axis = 0; axis < 3; ++axis)
        ASSERT_EQ(centre[axis], first[axis]) << cell;
      const CGAL::Epick::Point_3 permuted =
          CGAL::circumcenter(stub.corners[0]->position, stub.corners[1]->position,
                             stub.corners[2]->position, stub.corners[3]->position);
      orders_that_moved_the_plain_formula += permuted != plain;
    }
  }
  // Without the ordering the last bits would move: CGAL's own construction
  // does, on the same cells.
  EXPECT_GT(orders_that_moved_the_plain_formula, 100);
}

TEST(Scaffold, ObtuseGabrielTriangleIsTypeTwo) {
  const std::vector<Eigen::Vector3d> points = {{0, 0, 0}, {1, 0, 0}, {0.5, 0.2, 0}, {0.5, 0.1, 5}};
  const MedialScaffold scaffold = buildMedialScaffold(points, {});
  const Candidate *base = findCandidate(scaffold, {0, 1, 2});
  ASSERT_NE(base, nullptr);
  EXPECT_EQ(base->type, CandidateType::obtuse);
}

namespace {

/// A 5 x 5 x 5 grid of unit spacing, each coordinate moved by up to
/// `jitter` (uniform, seeded).
std::vector<Eigen::Vector3d> jitteredGrid(double jitter, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> offset(-jitter, jitter);
  std::vector<Eigen::Vector3d> points;
  for (int x = 0; x < 5; ++x)
    for (int y = 0; y < 5; ++y)
      for (int z = 0; z < 5; ++z)
        points.emplace_back(x + offset(random), y + offset(random), z + offset(random));
  return points;
}

} // namespace

// On a grid, right angles and co-circular corners go to CGAL's exact tests;
// on a jittered grid the floating-point filters decide: both must give the
// exact verdict on every Gabriel candidate.
TEST(Scaffold, AcuteAndObtuseTypesAgreeWithExactAngles) {
  using ExactPoint = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  for (double jitter : {0.0, 0.3}) {
    const std::vector<Eigen::Vector3d> points = jitteredGrid(jitter, 7);
    ScaffoldOptions options;
    options.rho = 100; // every facet is a candidate
    const MedialScaffold scaffold = buildMedialScaffold(points, options);
    std::size_t gabriel = 0, right_angles = 0;
    for (const Candidate &candidate : scaffold.candidates) {
      if (candidate.type == CandidateType::ambiguous)
        continue;
      ++gabriel;
      const auto corner = [&](int k) {
        const Eigen::Vector3d &p = points[candidate.vertices[k % 3]];
        return ExactPoint(p.x(), p.y(), p.z());
      };
      bool acute = true;
      for (int k = 0; k < 3; ++k) {
        const CGAL::Angle angle = CGAL::angle(corner(k + 1), corner(k), corner(k + 2));
        acute &= angle == CGAL::ACUTE;
        right_angles += angle == CGAL::RIGHT;
      }
      EXPECT_EQ(candidate.type == CandidateType::acute, acute);
    }
    EXPECT_GT(gabriel, 200u);
    EXPECT_EQ(right_angles > 0, jitter == 0) << "right angles: " << right_angles;
  }
}

// Types I and II are the Gabriel facets: no point strictly inside the
// smallest sphere through the corners, by CGAL's exact test against every
// point. On a grid many apexes lie exactly on such spheres (the exact
// fallback decides); a jitter of 1e-9 leaves near-ties within the filter's
// margin; a jitter of 0.3 lets the floating-point filter decide.
TEST(Scaffold, GabrielTypesAgreeWithExactDiametralSpheres) {
  using ExactPoint = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  const auto side_of_bounded_sphere =
      CGAL::Exact_predicates_inexact_constructions_kernel().side_of_bounded_sphere_3_object();
  for (double jitter : {0.0, 1e-9, 0.3}) {
    const std::vector<Eigen::Vector3d> points = jitteredGrid(jitter, 11);
    std::vector<ExactPoint> exact;
    for (const Eigen::Vector3d &p : points)
      exact.emplace_back(p.x(), p.y(), p.z());
    ScaffoldOptions options;
    options.rho = 100; // every facet is a candidate
    const MedialScaffold scaffold = buildMedialScaffold(points, options);
    std::size_t gabriel = 0, other = 0;
    for (const Candidate &candidate : scaffold.candidates) {
      const VertexIndex a = candidate.vertices[0], b = candidate.vertices[1],
                        c = candidate.vertices[2];
      const bool empty = std::none_of(exact.begin(), exact.end(), [&](const ExactPoint &p) {
        return side_of_bounded_sphere(exact[a], exact[b], exact[c], p) == CGAL::ON_BOUNDED_SIDE;
      });
      EXPECT_EQ(candidate.type != CandidateType::ambiguous, empty)
          << "jitter " << jitter << ", facet " << a << " " << b << " " << c;
      ++(empty ? gabriel : other);
    }
    EXPECT_GT(gabriel, 200u) << "jitter " << jitter;
    EXPECT_GT(other, 100u) << "jitter " << jitter;
  }
}

TEST(Scaffold, TriangleWithPointInItsDiametralSphereIsTypeThree) {
  // d hovers just above abc, well inside the sphere through a, b, c centred in their plane.
  const std::vector<Eigen::Vector3d> points = {
      {0, 0, 0}, {1, 0, 0}, {0.5, 0.9, 0}, {0.5, 0.3, 0.05}};
  const MedialScaffold scaffold = buildMedialScaffold(points, {});
  const Candidate *base = findCandidate(scaffold, {0, 1, 2});
  ASSERT_NE(base, nullptr);
  EXPECT_EQ(base->type, CandidateType::ambiguous);
  // Type III ranks with R = d_med.
  const TriangleShape shape = triangleShape(points[0], points[1], points[2]);
  EXPECT_NEAR(base->base_cost, baseCost(shape.perimeter, scaffold.d_med, shape.compactness),
              1e-4 * base->base_cost);
}

TEST(Scaffold, OversizeCandidatesAreNotKept) {
  // A unit square of four points and one far point: triangles to it exceed
  // d_max with rho = 1 and are counted as oversize.
  const std::vector<Eigen::Vector3d> points = {
      {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0.1}, {0.5, 0.5, 40}};
  ScaffoldOptions options;
  options.rho = 1.0;
  const MedialScaffold scaffold = buildMedialScaffold(points, options);
  EXPECT_GT(scaffold.oversize, 0u);
  for (const Candidate &candidate : scaffold.candidates)
    EXPECT_TRUE(std::find(candidate.vertices.begin(), candidate.vertices.end(), 4u) ==
                candidate.vertices.end());
}

TEST(Scaffold, PlanarGridGivesTwoDimensionalDelaunay) {
  std::vector<Eigen::Vector3d> grid;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      grid.emplace_back(i, j, 0);
  const MedialScaffold scaffold = buildMedialScaffold(grid, {});
  EXPECT_TRUE(scaffold.planar);
  EXPECT_EQ(scaffold.candidates.size(), 32u); // 16 squares, two triangles each
  EXPECT_NEAR(scaffold.d_med, std::sqrt(0.5), 1e-6);
}

TEST(Scaffold, FacetsTooThinForDoublesAreLeftOutNotNaN) {
  // A tiny tetrahedron and two far corners: a facet with one far corner and
  // two tiny ones is not collinear (exact predicates), but its edge vectors
  // are equal in double, so its circle would be 0 / 0. Such facets are left
  // out as degenerate. Their NaN radii made d_med and the local scales NaN,
  // and processes sharing such a cloud then meshed it otherwise than one.
  const double tiny = 1e-12;
  const std::vector<Eigen::Vector3d> points = {{0, 0, 0},
                                               {tiny, 0, 0},
                                               {0.3 * tiny, 0.9 * tiny, 0},
                                               {0.4 * tiny, 0.3 * tiny, 0.8 * tiny},
                                               {-1e31, 4e30, 2e30},
                                               {1e31, 2e30, -3e30}};
  const MedialScaffold scaffold = buildMedialScaffold(points, {});
  EXPECT_TRUE(std::isfinite(scaffold.d_med) && scaffold.d_med > 0) << scaffold.d_med;
  for (float scale : scaffold.local_scale)
    EXPECT_FALSE(std::isnan(scale));
  for (const Candidate &candidate : scaffold.candidates) {
    EXPECT_FALSE(std::isnan(candidate.base_cost));
    EXPECT_FALSE(std::isnan(candidate.inverse_shock_compactness));
  }
  // The candidate pass computes the circle again from the lowest-numbered
  // corner: the far ones first, and a size limit that keeps such facets,
  // make that circle 0 / 0 where the first pass's was finite.
  std::vector<Eigen::Vector3d> far_first(points.end() - 2, points.end());
  far_first.insert(far_first.end(), points.begin(), points.end() - 2);
  ScaffoldOptions no_size_limit;
  no_size_limit.rho = 1e60;
  const MedialScaffold far_first_scaffold = buildMedialScaffold(far_first, no_size_limit);
  EXPECT_GT(far_first_scaffold.degenerate, 0u);
  for (const Candidate &candidate : far_first_scaffold.candidates) {
    EXPECT_FALSE(std::isnan(candidate.base_cost));
    EXPECT_FALSE(std::isnan(candidate.inverse_shock_compactness));
  }
}

TEST(Scaffold, ScalesGivenForEveryPointAreUsedAsTheyAre) {
  // A seam zone's points all come with their buckets' scales, and the
  // scaffold then skips measuring them: it must build what it builds when
  // it measures (here forced by one point without a scale).
  const std::vector<Eigen::Vector3d> points = pcl_ms_test::bunnyReference().vertices;
  const MedialScaffold measured = buildMedialScaffold(points, {});
  std::vector<float> given = measured.local_scale;
  for (std::size_t v = 0; v < given.size(); ++v)
    given[v] *= v % 3 == 0 ? 1.5f : 0.8f; // not what the cloud would measure
  ScaffoldOptions options;
  options.local_scale = &given;
  const MedialScaffold all_given = buildMedialScaffold(points, options);
  EXPECT_EQ(all_given.local_scale, given);
  EXPECT_EQ(all_given.d_med, measured.d_med);
  EXPECT_EQ(all_given.d_max, options.rho * measured.d_med);

  const VertexIndex unscaled = 1000;
  std::vector<float> one_missing = given;
  one_missing[unscaled] = 0;
  options.local_scale = &one_missing;
  const MedialScaffold measuring = buildMedialScaffold(points, options);
  EXPECT_EQ(measuring.d_med, measured.d_med);
  auto awayFromUnscaled = [&](const MedialScaffold &scaffold) {
    std::vector<std::pair<Triangle, float>> kept;
    for (const Candidate &candidate : scaffold.candidates)
      if (std::find(candidate.vertices.begin(), candidate.vertices.end(), unscaled) ==
          candidate.vertices.end())
        kept.emplace_back(candidate.vertices, candidate.base_cost);
    return kept;
  };
  const auto expected = awayFromUnscaled(measuring);
  EXPECT_GT(expected.size(), 100000u);
  EXPECT_EQ(awayFromUnscaled(all_given), expected);
}

TEST(Scaffold, CollinearPointsAreRejected) {
  const std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}};
  EXPECT_THROW(buildMedialScaffold(line, {}), ReconstructionError);
}

// ---- mesh topology ---------------------------------------------------------------

TEST(MeshTopology, CountsFollowAddAndRemove) {
  const MedialScaffold scaffold = buildMedialScaffold(regularTetrahedron(), {});
  MeshTopology mesh(scaffold, 4);
  mesh.add(0);
  for (VertexIndex v : scaffold.candidates[0].vertices) {
    EXPECT_EQ(mesh.vertexBoundaryEdges(v), 2);
    EXPECT_FALSE(mesh.isClosedVertex(v));
  }
  mesh.add(1);
  int shared = 0;
  for (EdgeIndex e = 0; e < scaffold.numberOfEdges(); ++e)
    shared += mesh.edgeTriangleCount(e) == 2;
  EXPECT_EQ(shared, 1);
  mesh.add(2);
  mesh.add(3);
  EXPECT_EQ(mesh.size(), 4u);
  for (VertexIndex v = 0; v < 4; ++v) {
    EXPECT_TRUE(mesh.isClosedVertex(v));
    EXPECT_EQ(mesh.fansAround(v).size(), 1u);
    EXPECT_EQ(mesh.vertexTriangles(v).size(), 3u);
  }
  mesh.remove(3);
  EXPECT_FALSE(mesh.contains(3));
  for (VertexIndex v : scaffold.candidates[3].vertices)
    EXPECT_FALSE(mesh.isClosedVertex(v));
}

TEST(MeshTopology, EdgesAtAVertexThatIsNoCornerIsAnErrorNotEdgeZero) {
  const MedialScaffold scaffold = buildMedialScaffold(regularTetrahedron(), {});
  const MeshTopology mesh(scaffold, 4);
  const auto &corners = scaffold.candidates[0].vertices;
  const auto edges = mesh.edgesAt(0, corners[1]);
  EXPECT_EQ(edges[0], scaffold.candidates[0].edges[1]);
  EXPECT_EQ(edges[1], scaffold.candidates[0].edges[0]);
  VertexIndex missing = 0;
  while (std::find(corners.begin(), corners.end(), missing) != corners.end())
    ++missing;
  EXPECT_THROW(mesh.edgesAt(0, missing), std::logic_error);
}

namespace {

/// A scaffold holding just the given triangles as candidates, edges numbered
/// by hand (MeshTopology needs nothing else).
MedialScaffold scaffoldOfTriangles(const std::vector<Triangle> &triangles) {
  MedialScaffold scaffold;
  std::map<std::pair<VertexIndex, VertexIndex>, EdgeIndex> edge_ids;
  for (Triangle vertices : triangles) {
    std::sort(vertices.begin(), vertices.end());
    Candidate candidate{};
    candidate.vertices = vertices;
    for (int k = 0; k < 3; ++k) {
      const auto key = std::minmax(vertices[k], vertices[(k + 1) % 3]);
      candidate.edges[k] =
          edge_ids.emplace(key, static_cast<EdgeIndex>(edge_ids.size())).first->second;
    }
    scaffold.candidates.push_back(candidate);
  }
  scaffold.edge_offsets.assign(edge_ids.size() + 1, 0);
  return scaffold;
}

} // namespace

TEST(MeshTopology, SingleAndClosedFanTestsAgreeWithTheFans) {
  // Vertex 0 is the centre of a closed ring of six triangles and of a
  // separate open fan of two: every subset of them is tried. A fan is closed
  // when every edge its triangles have at the vertex holds two triangles.
  std::vector<Triangle> triangles;
  for (VertexIndex i = 1; i <= 6; ++i)
    triangles.push_back({0, i, i % 6 + 1});
  triangles.push_back({0, 7, 8});
  triangles.push_back({0, 8, 9});
  const MedialScaffold scaffold = scaffoldOfTriangles(triangles);
  int several_fans = 0, closed_beside_others = 0, one_fan_three_inside = 0;
  for (unsigned subset = 0; subset < (1u << triangles.size()); ++subset) {
    MeshTopology mesh(scaffold, 10);
    for (CandidateIndex t = 0; t < triangles.size(); ++t)
      if (subset & (1u << t))
        mesh.add(t);
    for (VertexIndex v = 0; v < 10; ++v) {
      const auto fans = mesh.fansAround(v);
      ASSERT_EQ(mesh.isSingleFan(v), fans.size() <= 1) << "vertex " << v << ", subset " << subset;
      // Where there is one fan, the walk counts the triangles inside it.
      int inner_counted = -1;
      if (mesh.isSingleFan(v, inner_counted)) {
        int inner = 0;
        for (CandidateIndex t : mesh.vertexTriangles(v))
          inner += mesh.isInnerAt(t, v);
        ASSERT_EQ(inner_counted, inner) << "vertex " << v << ", subset " << subset;
        one_fan_three_inside += inner >= 3;
      }
      bool closed = false;
      for (const auto &fan : fans) {
        const bool fan_closed = std::all_of(fan.begin(), fan.end(), [&](CandidateIndex t) {
          const auto edges = mesh.edgesAt(t, v);
          return mesh.edgeTriangleCount(edges[0]) == 2 && mesh.edgeTriangleCount(edges[1]) == 2;
        });
        // The walk from one triangle finds its own fan's ring only.
        for (CandidateIndex t : fan)
          ASSERT_EQ(mesh.isInClosedFan(t, v), fan_closed)
              << "triangle " << t << ", vertex " << v << ", subset " << subset;
        closed |= fan_closed;
      }
      ASSERT_EQ(mesh.hasClosedFan(v), closed) << "vertex " << v << ", subset " << subset;
      closed_beside_others += closed && fans.size() > 1;
    }
    several_fans += !mesh.isSingleFan(0);
  }
  // Sanity check of the enumeration: bow-ties at the centre are common, and
  // the closed ring meets the open fan in three subsets.
  EXPECT_GT(several_fans, 100);
  EXPECT_EQ(closed_beside_others, 3);
  // One fan with three or more inside: at the centre, the whole ring (six
  // inside) or the ring less one triangle (five in a row, three inside),
  // without the open fan.
  EXPECT_EQ(one_fan_three_inside, 7);
}

// ---- greedy ------------------------------------------------------------------------

TEST(Greedy, TetrahedronClosesIntoFourTriangles) {
  MedialScaffold scaffold = buildMedialScaffold(regularTetrahedron(), {});
  const std::vector<Eigen::Vector3d> points = regularTetrahedron();
  Parameters parameters;
  GreedyMesher mesher(std::move(scaffold), points, parameters);
  mesher.run();
  EXPECT_EQ(mesher.triangles().size(), 4u);
  EXPECT_EQ(mesher.statistics().pass1.accepted, 4u);
}

TEST(Greedy, CubeCornersGiveTheSixSquareFaces) {
  const Result result = runOn(cubeCorners());
  ASSERT_EQ(result.triangles.size(), 12u);
  for (const Triangle &t : result.triangles) {
    // Every triangle lies in a face: its three corners share one coordinate.
    const auto corners = cubeCorners();
    bool on_face = false;
    for (int axis = 0; axis < 3; ++axis)
      on_face |=
          corners[t[0]][axis] == corners[t[1]][axis] && corners[t[1]][axis] == corners[t[2]][axis];
    EXPECT_TRUE(on_face);
  }
  EXPECT_TRUE(result.boundary_loops.empty());
  ASSERT_EQ(result.numberOfComponents(), 1u);
  EXPECT_TRUE(result.component_orientable[0]);
}

TEST(Greedy, SphereSamplingIsAClosedGenusZeroSurface) {
  const std::vector<float> xyz = pcl_ms_test::fibonacciSphere(400);
  const Result result = reconstruct(pcl_ms_test::viewOf(xyz), {});
  const MeshTopologyReport report = analyzeMesh(pcl_ms_test::positions(xyz), result.triangles);
  expectCleanManifold(report);
  EXPECT_EQ(report.boundary_edges, 0u);
  EXPECT_EQ(report.components, 1u);
  EXPECT_EQ(report.euler_characteristic, 2);
  EXPECT_EQ(report.referenced_vertices, 400u);
  EXPECT_TRUE(report.orientable);
  EXPECT_EQ(report.inconsistently_oriented_edges, 0u);
  EXPECT_EQ(result.triangles.size(), 2u * 400 - 4);
}

// ---- bow-ties ------------------------------------------------------------------------

TEST(BowTies, OneRuleRanksFixedThenPreferredThenSizeThenCost) {
  using detail::FanWeight;
  const auto keep = [](const std::vector<FanWeight> &fans) {
    return detail::fanToKeep(fans.size(), [&](std::size_t f) { return fans[f]; });
  };
  // fixed, preferred, size, cost
  EXPECT_EQ(keep({{0, 0, 9, 0.0}, {1, 0, 1, 5.0}}), 1u);
  EXPECT_EQ(keep({{0, 0, 9, 0.0}, {0, 2, 1, 5.0}, {0, 1, 9, 0.0}}), 1u);
  EXPECT_EQ(keep({{0, 0, 2, 0.0}, {0, 0, 3, 9.0}}), 1u);
  EXPECT_EQ(keep({{0, 0, 3, 2.0}, {0, 0, 3, 1.0}, {0, 0, 3, 1.5}}), 1u);
  EXPECT_EQ(keep({{0, 0, 3, 1.0}, {0, 0, 3, 1.0}}), 0u); // full tie: the first
}

TEST(BowTies, SplitKeepsTheLargerFanAndRechecksTheCornersOfWhatItRemoves) {
  // Vertex 0 has a fan of three triangles and one of two; the small fan's
  // removal leaves vertex 7 between two fans of its own, the larger of
  // which (7, 8, 9), (7, 9, 10) stays.
  std::vector<Triangle> triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4},  {0, 5, 6},
                                     {0, 6, 7}, {7, 8, 9}, {7, 9, 10}, {6, 7, 11}};
  std::vector<bool> touched(12, false);
  touched[0] = true;
  const std::size_t removed = splitBowTies(triangles, 12, touched);
  const std::vector<Triangle> expected = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {7, 8, 9}, {7, 9, 10}};
  EXPECT_EQ(triangles, expected);
  EXPECT_EQ(removed, 3u);

  // Equal fans: the first (by lowest triangle) stays.
  std::vector<Triangle> pair = {{0, 1, 2}, {0, 3, 4}};
  std::vector<bool> at_zero(5, false);
  at_zero[0] = true;
  EXPECT_EQ(splitBowTies(pair, 5, at_zero), 1u);
  EXPECT_EQ(pair, (std::vector<Triangle>{{0, 1, 2}}));
}

TEST(BowTies, SplitNeverRemovesFixedTriangles) {
  // As above, with the small fan at vertex 0 holding a fixed triangle: it
  // stays and the larger fan goes.
  const std::vector<Triangle> bow_tie = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4},  {0, 5, 6},
                                         {0, 6, 7}, {7, 8, 9}, {7, 9, 10}, {6, 7, 11}};
  std::vector<Triangle> triangles = bow_tie;
  std::vector<bool> touched(12, false);
  touched[0] = true;
  const std::vector<Triangle> one_fixed = {{0, 5, 6}};
  EXPECT_EQ(splitBowTies(triangles, 12, touched, &one_fixed), 3u);
  EXPECT_EQ(triangles,
            (std::vector<Triangle>{{0, 5, 6}, {0, 6, 7}, {7, 8, 9}, {7, 9, 10}, {6, 7, 11}}));

  // Both fans hold one: the larger stays whole, the other loses only what
  // is not fixed, and vertex 0 stays a pinch.
  triangles = bow_tie;
  std::fill(touched.begin(), touched.end(), false);
  touched[0] = true;
  const std::vector<Triangle> two_fixed = {{0, 1, 2}, {0, 5, 6}};
  EXPECT_EQ(splitBowTies(triangles, 12, touched, &two_fixed), 2u);
  EXPECT_EQ(triangles, (std::vector<Triangle>{
                           {0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 5, 6}, {7, 8, 9}, {7, 9, 10}}));
}

TEST(BowTies, ManyPinchesSplitTheSameOnOneAndTwoThreads) {
  // 12,000 bow-ties, more than one block of vertices per thread: at each
  // centre a fan of two triangles stays and a lone triangle goes. Centres
  // are 6 apart, so the marked vertices fall in every 64-vertex word of the
  // rank lookup, some words dense (every vertex of the first 600 marked).
  constexpr VertexIndex pinches = 12000, stride = 6;
  std::vector<Triangle> bow_ties, expected;
  std::vector<bool> touched(pinches * stride, false);
  for (VertexIndex k = 0; k < pinches; ++k) {
    const VertexIndex c = k * stride;
    bow_ties.push_back({c, c + 1, c + 2});
    bow_ties.push_back({c, c + 2, c + 3});
    bow_ties.push_back({c, c + 4, c + 5});
    expected.push_back({c, c + 1, c + 2});
    expected.push_back({c, c + 2, c + 3});
    touched[c] = true;
  }
  std::fill(touched.begin(), touched.begin() + 600, true);
  for (int threads : {1, 2}) {
    std::vector<Triangle> triangles = bow_ties;
    std::vector<bool> marked = touched;
    const std::size_t removed = detail::withThreads(
        threads, [&] { return splitBowTies(triangles, touched.size(), marked); });
    EXPECT_EQ(removed, std::size_t{pinches}) << threads << " threads";
    EXPECT_EQ(triangles, expected) << threads << " threads";
  }
}

// ---- finish --------------------------------------------------------------------------

TEST(Finish, BoundaryLoopOfTwoTriangles) {
  const std::vector<Triangle> square = {{0, 1, 2}, {0, 2, 3}};
  const auto loops = traceBoundaryLoops(square);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0], (std::vector<VertexIndex>{0, 1, 2, 3}));
}

namespace {

void expectSameEdges(const detail::MeshEdges &found, const detail::MeshEdges &expected) {
  EXPECT_EQ(found.boundary, expected.boundary);
  EXPECT_EQ(found.boundary_triangle, expected.boundary_triangle);
  EXPECT_TRUE(found.neighbours == expected.neighbours);
  EXPECT_EQ(found.crowded, expected.crowded);
}

} // namespace

// The edge scan sorts incidences a block of vertices at a time; any block
// size must find the same edges in the same order (the bunny's reference
// mesh: open at the base, so both kinds).
TEST(Finish, EdgeScanDoesNotDependOnTheBlockSize) {
  const std::vector<Triangle> &triangles = pcl_ms_test::bunnyReference().triangles;
  const detail::MeshEdges whole = detail::meshEdges(triangles, true);
  ASSERT_FALSE(whole.boundary.empty());
  ASSERT_EQ(whole.neighbours.size(), 3 * triangles.size());
  const std::size_t neighbour_slots = static_cast<std::size_t>(
      std::count_if(whole.neighbours.begin(), whole.neighbours.end(),
                    [](std::uint32_t u) { return u != detail::no_neighbour; }));
  EXPECT_EQ(neighbour_slots + whole.boundary.size(), 3 * triangles.size());
  EXPECT_TRUE(std::is_sorted(whole.boundary.begin(), whole.boundary.end()));
  // Neighbourhood is mutual.
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      if (const std::uint32_t u = whole.neighbours[3 * t + k]; u != detail::no_neighbour) {
        const auto *theirs = &whole.neighbours[3 * std::size_t{u}];
        ASSERT_NE(std::find(theirs, theirs + 3, t), theirs + 3) << t << " " << u;
      }
  // Threads file the incidences in any order: one thread must find the same.
  detail::MeshEdges one_thread;
  detail::withThreads(1, [&] { one_thread = detail::meshEdges(triangles, true); });
  expectSameEdges(one_thread, whole);
#if defined(__SANITIZE_THREAD__)
  // Each block scans every triangle: 208 blocks of 1,000 took 26 minutes
  // under ThreadSanitizer, where 11 check the same joins.
  constexpr std::size_t small_block = 20000;
#else
  constexpr std::size_t small_block = 1000;
#endif
  for (std::size_t block : {small_block, std::size_t(77777)}) {
    SCOPED_TRACE(block);
    expectSameEdges(detail::meshEdges(triangles, true, block), whole);
  }
  // Blocks of one vertex and of a few incidences scan every triangle for
  // each block (47 s on the whole mesh, 8 minutes under ASan): they run on
  // its first 600 triangles, a patch with boundary and manifold edges.
  const std::vector<Triangle> base(triangles.begin(), triangles.begin() + 600);
  const detail::MeshEdges base_whole = detail::meshEdges(base, true);
  ASSERT_FALSE(base_whole.boundary.empty());
  ASSERT_LT(
      std::count(base_whole.neighbours.begin(), base_whole.neighbours.end(), detail::no_neighbour),
      static_cast<std::ptrdiff_t>(base_whole.neighbours.size()));
  for (std::size_t block : {std::size_t(1), std::size_t(5)}) {
    SCOPED_TRACE(block);
    expectSameEdges(detail::meshEdges(base, true, block), base_whole);
  }
  EXPECT_EQ(traceBoundaryLoops(triangles), detail::boundaryLoops(whole.boundary));
}

// A patch of the bunny's reference mesh (its first 15,000 triangles: the
// whole mesh takes minutes under ThreadSanitizer) with every `every`-th
// triangle taken out.
namespace {

std::vector<Triangle> holedBunnyPatch(std::size_t every) {
  const std::vector<Triangle> &all = pcl_ms_test::bunnyReference().triangles;
  std::vector<Triangle> holed;
  for (std::size_t t = 0; t < 15000; ++t)
    if (t % every != 0)
      holed.push_back(all[t]);
  return holed;
}

} // namespace

// Finishing updates the edge scan for the hole fillings instead of scanning
// again: the update must give exactly what a new scan gives. Holes of 3 to
// 9 edges beside the patch's rim, and loops that stay open.
TEST(Finish, FillingUpdateMatchesANewEdgeScan) {
  const pcl_ms_test::ReferenceMesh &bunny = pcl_ms_test::bunnyReference();
  std::vector<Triangle> triangles = holedBunnyPatch(47);
  detail::MeshEdges edges = detail::meshEdges(triangles, true);
  ASSERT_EQ(edges.boundary_triangle.size(), edges.boundary.size());
  const std::vector<float> scale(bunny.vertices.size(), 0.002f);
  std::vector<Triangle> filling;
  const std::size_t filled =
      detail::fillLoops(triangles, detail::boundaryLoops(edges.boundary), bunny.vertices, 9,
                        SideLimit{&scale, 5.0}, nullptr, filling);
  ASSERT_GT(filled, 200u);
  const std::size_t first_new = triangles.size(), open_edges = edges.boundary.size();
  triangles.insert(triangles.end(), filling.begin(), filling.end());
  detail::addFilling(edges, triangles, first_new);
  const detail::MeshEdges scanned = detail::meshEdges(triangles, true);
  expectSameEdges(edges, scanned);
  // The update closed edges and kept others: some loops stayed open.
  EXPECT_LT(scanned.boundary.size(), open_edges);
  EXPECT_FALSE(scanned.boundary.empty());
}

// The twist repair and the bow-tie split drop triangles; finishing updates
// the edge scan for them instead of scanning again. The update must give
// exactly what a new scan gives: scattered triangles, triangles with their
// neighbours, rim triangles, none, all, and a list with an edge of three
// triangles (no slots to update: scanned again).
TEST(Finish, DropUpdateMatchesANewEdgeScan) {
  const std::vector<Triangle> patch = holedBunnyPatch(47);
  const detail::MeshEdges patch_edges = detail::meshEdges(patch, true);
  auto expectDropMatchesScan = [](std::vector<Triangle> triangles, detail::MeshEdges edges,
                                  const std::vector<bool> &drop) {
    const std::size_t kept = static_cast<std::size_t>(std::count(drop.begin(), drop.end(), false));
    std::vector<bool> touched(200000, false);
    detail::dropTriangles(triangles, drop, touched, &edges);
    ASSERT_EQ(triangles.size(), kept);
    expectSameEdges(edges, detail::meshEdges(triangles, true));
  };
  std::vector<bool> drop(patch.size(), false);
  {
    SCOPED_TRACE("scattered");
    for (std::size_t t = 0; t < patch.size(); t += 13)
      drop[t] = true;
    expectDropMatchesScan(patch, patch_edges, drop);
  }
  {
    SCOPED_TRACE("with their neighbours");
    std::fill(drop.begin(), drop.end(), false);
    for (std::size_t t = 5; t < patch.size(); t += 101) {
      drop[t] = true;
      for (std::size_t k = 3 * t; k < 3 * t + 3; ++k)
        if (patch_edges.neighbours[k] != detail::no_neighbour)
          drop[patch_edges.neighbours[k]] = true;
    }
    expectDropMatchesScan(patch, patch_edges, drop);
  }
  {
    SCOPED_TRACE("on the rim");
    std::fill(drop.begin(), drop.end(), false);
    for (std::size_t e = 0; e < patch_edges.boundary_triangle.size(); e += 3)
      drop[patch_edges.boundary_triangle[e]] = true;
    expectDropMatchesScan(patch, patch_edges, drop);
  }
  {
    SCOPED_TRACE("none, then all");
    std::fill(drop.begin(), drop.end(), false);
    expectDropMatchesScan(patch, patch_edges, drop);
    std::fill(drop.begin(), drop.end(), true);
    expectDropMatchesScan(patch, patch_edges, drop);
  }
  {
    SCOPED_TRACE("an edge of three triangles");
    const std::vector<Triangle> fin = {{0, 1, 2}, {0, 1, 3}, {0, 1, 4}, {1, 2, 5}, {2, 5, 6}};
    const detail::MeshEdges fin_edges = detail::meshEdges(fin, true);
    detail::MeshEdges unchanged = fin_edges;
    EXPECT_FALSE(detail::dropFromMeshEdges(unchanged, fin, {false, false, false, true, false}));
    expectSameEdges(unchanged, fin_edges);
    expectDropMatchesScan(fin, fin_edges, {false, false, false, true, false});
    expectDropMatchesScan(fin, fin_edges, {false, true, false, false, false});
  }
}

// The bow-tie split keeps the edge scan it is given up to date: it takes
// what its two rounds remove out of the list at the end (the example of
// BowTies.SplitKeepsTheLargerFan...).
TEST(Finish, BowTieSplitKeepsTheEdgeScanUpToDate) {
  std::vector<Triangle> triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4},  {0, 5, 6},
                                     {0, 6, 7}, {7, 8, 9}, {7, 9, 10}, {6, 7, 11}};
  detail::MeshEdges edges = detail::meshEdges(triangles, true);
  std::vector<bool> touched(12, false);
  touched[0] = true;
  EXPECT_EQ(detail::splitBowTies(triangles, 12, touched, nullptr, &edges), 3u);
  EXPECT_EQ(triangles.size(), 5u);
  expectSameEdges(edges, detail::meshEdges(triangles, true));
}

// Finishing keeps room for the fillings beside the triangle list (1/256 of
// it plus 64); more fillings move the list and scan it again. Either way
// the surface is the list with its fillings, oriented, loops traced anew:
// the patch with every 497th triangle taken out (within the room) and
// every 47th (beyond it).
TEST(Finish, FillingsWithinAndBeyondTheRoomGiveTheFilledSurface) {
  const pcl_ms_test::ReferenceMesh &bunny = pcl_ms_test::bunnyReference();
  const std::vector<float> scale(bunny.vertices.size(), 0.002f);
  const SideLimit limit{&scale, 5.0};
  for (const std::size_t every : {std::size_t(497), std::size_t(47)}) {
    SCOPED_TRACE(every);
    const std::vector<Triangle> holed = holedBunnyPatch(every);
    // The patch's ragged rim has loops of up to 9 edges: within the room,
    // only the triangular holes are filled.
    const int max_edges = every == 47 ? 9 : 3;
    std::vector<Triangle> filling;
    const std::size_t filled = detail::fillLoops(holed, traceBoundaryLoops(holed), bunny.vertices,
                                                 max_edges, limit, nullptr, filling);
    const bool beyond = filling.size() > holed.size() / 256 + 64;
    EXPECT_EQ(beyond, every == 47) << filling.size() << " filling triangles";

    const FinishedSurface surface = finishSurface(holed, bunny.vertices, max_edges, limit);
    EXPECT_EQ(surface.holes_filled, filled);
    EXPECT_EQ(surface.twist_triangles_removed, 0u);
    std::vector<Triangle> expected = holed;
    expected.insert(expected.end(), filling.begin(), filling.end());
    auto corners = [](std::vector<Triangle> triangles) {
      for (Triangle &triangle : triangles)
        std::sort(triangle.begin(), triangle.end());
      std::sort(triangles.begin(), triangles.end());
      return triangles;
    };
    EXPECT_EQ(corners(surface.triangles), corners(expected));
    EXPECT_EQ(surface.boundary_loops, traceBoundaryLoops(surface.triangles));
    // Holes that touch at a corner stay open and pinch it; edges stay manifold.
    const MeshTopologyReport report = analyzeMesh(bunny.vertices, surface.triangles);
    EXPECT_EQ(report.non_manifold_edges, 0u);
    EXPECT_EQ(report.inconsistently_oriented_edges, 0u);
  }
}

TEST(Finish, FillsTheMissingFaceOfACube) {
  const std::vector<Eigen::Vector3d> corners = cubeCorners();
  // The cube's faces as two triangles each, the top (z = 1) left out.
  const std::vector<Triangle> open_box = {{0, 2, 1}, {1, 2, 3}, {0, 1, 5}, {0, 5, 4}, {1, 3, 7},
                                          {1, 7, 5}, {3, 2, 6}, {3, 6, 7}, {2, 0, 4}, {2, 4, 6}};
  const std::vector<float> unit_scale(corners.size(), 1.0f); // sides below rho
  FinishedSurface kept = finishSurface(open_box, corners, 3, SideLimit{&unit_scale, 10.0});
  EXPECT_EQ(kept.holes_filled, 0u); // the hole has 4 edges, more than 3
  EXPECT_EQ(kept.boundary_loops.size(), 1u);
  // A hole of four edges is closed whatever the size limit: its filling's
  // new side is at most two of its edges long.
  FinishedSurface small_limit = finishSurface(open_box, corners, 4, SideLimit{&unit_scale, 1.2});
  EXPECT_EQ(small_limit.holes_filled, 1u);
  FinishedSurface closed = finishSurface(open_box, corners, 4, SideLimit{&unit_scale, 10.0});
  EXPECT_EQ(closed.holes_filled, 1u);
  EXPECT_EQ(closed.triangles.size(), 12u);
  EXPECT_TRUE(closed.boundary_loops.empty());
  const MeshTopologyReport report = analyzeMesh(corners, closed.triangles);
  expectCleanManifold(report);
  EXPECT_EQ(report.euler_characteristic, 2);
  EXPECT_EQ(report.inconsistently_oriented_edges, 0u);
}

TEST(Finish, LargerHolesKeepTheLocalSizeLimit) {
  // A pentagonal cone open at the top: the filling's diagonals are 1.90
  // times the rim's radius of 1.
  std::vector<Eigen::Vector3d> points = {{0, 0, 0}};
  for (int k = 0; k < 5; ++k)
    points.emplace_back(std::cos(2 * M_PI * k / 5), std::sin(2 * M_PI * k / 5), 1.0);
  std::vector<Triangle> cone;
  for (VertexIndex k = 0; k < 5; ++k)
    cone.push_back({0, 1 + k, 1 + (k + 1) % 5});
  const std::vector<float> unit_scale(points.size(), 1.0f);
  const FinishedSurface too_small = finishSurface(cone, points, 8, SideLimit{&unit_scale, 1.8});
  EXPECT_EQ(too_small.holes_filled, 0u);
  EXPECT_EQ(too_small.boundary_loops.size(), 1u);
  // The limit is rho times the local scale of the filling's corners.
  std::vector<float> sparser_rim(points.size(), 1.2f);
  sparser_rim[0] = 1.0f;
  const FinishedSurface closed = finishSurface(cone, points, 8, SideLimit{&sparser_rim, 1.8});
  EXPECT_EQ(closed.holes_filled, 1u);
  EXPECT_TRUE(closed.boundary_loops.empty());
  EXPECT_EQ(closed.triangles.size(), 8u);
}

TEST(Finish, OrientsClosedSurfacesOutward) {
  const std::vector<Eigen::Vector3d> points = regularTetrahedron();
  std::vector<Triangle> faces = {{0, 1, 2}, {0, 1, 3}, {1, 2, 3}, {0, 2, 3}}; // mixed orientation
  std::vector<std::uint32_t> component;
  std::vector<bool> orientable;
  orientComponents(faces, points, component, orientable);
  ASSERT_EQ(orientable.size(), 1u);
  EXPECT_TRUE(orientable[0]);
  const Eigen::Vector3d centre = (points[0] + points[1] + points[2] + points[3]) / 4;
  for (const Triangle &t : faces) {
    const Eigen::Vector3d normal = (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]);
    EXPECT_GT(normal.dot(points[t[0]] - centre), 0) << "face points inward";
  }
}

TEST(Finish, GentleMoebiusBandIsKeptWhole) {
  // A finely sampled band: its twist bends no edge sharply, so finishing
  // must keep every triangle and report the band as non-orientable.
  std::vector<Eigen::Vector3d> points;
  std::vector<Triangle> band;
  moebiusBand(60, 0.2, points, band);
  const std::vector<float> unit_scale(points.size(), 1.0f);
  const FinishedSurface surface = finishSurface(band, points, 8, SideLimit{&unit_scale, 10.0});
  EXPECT_EQ(surface.triangles.size(), band.size());
  EXPECT_EQ(surface.twist_triangles_removed, 0u);
  ASSERT_EQ(surface.component_orientable.size(), 1u);
  EXPECT_FALSE(surface.component_orientable[0]);
  EXPECT_EQ(surface.boundary_loops.size(), 1u);
}

TEST(Finish, TwistIsLocalUpToThirtyTwoTriangles) {
  // A band of 2n triangles reverses orientation only all the way round, a
  // walk of exactly 2n triangles; its edges bend by less than 90 degrees.
  // A walk of up to 32 triangles makes the twist local (cut); 34 does not,
  // and 2 sqrt(34) allows no longer walk.
  for (const int segments : {15, 16, 17}) {
    SCOPED_TRACE(segments);
    std::vector<Eigen::Vector3d> points;
    std::vector<Triangle> band;
    moebiusBand(segments, 0.2, points, band);
    const std::vector<float> unit_scale(points.size(), 1.0f);
    const FinishedSurface surface = finishSurface(band, points, 0, SideLimit{&unit_scale, 10.0});
    if (segments <= 16)
      EXPECT_GT(surface.twist_triangles_removed, 0u);
    else
      EXPECT_EQ(surface.twist_triangles_removed, 0u);
  }
}

TEST(Finish, SameSurfaceForAnyNumberOfThreads) {
  // Long enough for the parallel loops to split the work; non-orientable,
  // so the spanning-forest orientation runs as well.
  std::vector<Eigen::Vector3d> points;
  std::vector<Triangle> band;
  moebiusBand(6000, 0.2, points, band);
  const std::vector<float> unit_scale(points.size(), 1.0f);
  auto finishWith = [&](int threads) {
    FinishedSurface surface;
    detail::withThreads(threads, [&] {
      surface = finishSurface(band, points, 8, SideLimit{&unit_scale, 10.0});
    });
    return surface;
  };
  const FinishedSurface one = finishWith(1);
  ASSERT_EQ(one.component_orientable, std::vector<bool>{false});
  for (int threads : {2, 8}) {
    const FinishedSurface several = finishWith(threads);
    EXPECT_EQ(several.triangles, one.triangles) << threads << " threads";
    EXPECT_EQ(several.boundary_loops, one.boundary_loops) << threads << " threads";
    EXPECT_EQ(several.triangle_component, one.triangle_component) << threads << " threads";
  }
}

namespace {

/// A flat ring of `segments` quads (radii 0.8 to 1.2) whose last quad is
/// glued with a half twist, i.e. crossed over itself.
void crossedBand(int segments, std::vector<Eigen::Vector3d> &points, std::vector<Triangle> &band) {
  for (int i = 0; i < segments; ++i) {
    const double angle = 2 * M_PI * i / segments;
    for (double radius : {0.8, 1.2})
      points.emplace_back(radius * std::cos(angle), radius * std::sin(angle), 0.0);
  }
  for (int i = 0; i < segments; ++i) {
    const VertexIndex a = 2 * i, b = 2 * i + 1;
    VertexIndex c = 2 * ((i + 1) % segments), d = c + 1;
    if (i == segments - 1)
      std::swap(c, d);
    band.push_back({a, b, d});
    band.push_back({a, d, c});
  }
}

} // namespace

TEST(Finish, TwistIsCutWhereTheBandFoldsOverItself) {
  // A flat ring of quads whose last quad is glued with a half twist, i.e.
  // crossed over itself: every edge is flat except around that quad. The
  // inconsistent edge that orientation must leave belongs there, however
  // far it is from where orientation starts (triangle 0).
  const int segments = 40;
  std::vector<Eigen::Vector3d> points;
  std::vector<Triangle> band;
  crossedBand(segments, points, band);
  std::vector<std::uint32_t> component;
  std::vector<bool> orientable;
  orientComponents(band, points, component, orientable);
  ASSERT_EQ(orientable, std::vector<bool>{false});
  auto runsFromTo = [](const Triangle &t, VertexIndex from, VertexIndex to) {
    for (int k = 0; k < 3; ++k)
      if (t[k] == from && t[(k + 1) % 3] == to)
        return true;
    return false;
  };
  const std::size_t crossed_quad = 2 * (segments - 1);
  std::size_t inconsistent_edges = 0;
  for (std::size_t t = 0; t < band.size(); ++t)
    for (std::size_t u = t + 1; u < band.size(); ++u)
      for (int k = 0; k < 3; ++k)
        if (runsFromTo(band[u], band[t][k], band[t][(k + 1) % 3])) {
          ++inconsistent_edges; // both run the shared edge the same way
          EXPECT_TRUE(t >= crossed_quad || u >= crossed_quad)
              << "inconsistent edge between triangles " << t << " and " << u;
        }
  EXPECT_EQ(inconsistent_edges, 1u);
}

TEST(Finish, FoldsLoseOnlyTheTrianglesAtTheInconsistentEdge) {
  // A flat annulus of quads with one quad crossed over itself: a sharp fold
  // that no orientation can get through. Cutting it must not cost more than
  // that quad's triangles (cutting the worst corner's fan, as before, took 3).
  std::vector<Eigen::Vector3d> points;
  std::vector<Triangle> band;
  crossedBand(40, points, band);
  const std::vector<float> scale(points.size(), 1.0f);
  const FinishedSurface surface = finishSurface(band, points, 0, SideLimit{&scale, 5.0});
  EXPECT_LE(surface.twist_triangles_removed, 2u);
  EXPECT_EQ(surface.triangles.size() + surface.twist_triangles_removed, band.size());
  ASSERT_EQ(surface.component_orientable, std::vector<bool>{true});
  expectCleanManifold(analyzeMesh(points, surface.triangles));
}

TEST(Finish, MoebiusStripIsReportedNonOrientable) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Triangle> strip;
  moebiusBand(5, 0.3, points, strip);
  std::vector<std::uint32_t> component;
  std::vector<bool> orientable;
  orientComponents(strip, points, component, orientable);
  ASSERT_EQ(orientable.size(), 1u);
  EXPECT_FALSE(orientable[0]);
  EXPECT_EQ(traceBoundaryLoops(strip).size(), 1u); // a Moebius strip has one boundary curve
}
