// SPDX-License-Identifier: GPL-3.0-or-later
// Triangle shape measures and the two cost terms of the paper (Eq. 1 and 2).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace pcl_ms {

/// Side lengths, perimeter, area and compactness of a triangle.
struct TriangleShape {
  double longest_side = 0;
  double perimeter = 0;
  double area = 0;
  /// 4 sqrt(3) A / (d1^2 + d2^2 + d3^2): 1 for equilateral, 0 for degenerate.
  double compactness = 0;
};

inline TriangleShape triangleShape(const Eigen::Vector3d &a, const Eigen::Vector3d &b,
                                   const Eigen::Vector3d &c) {
  TriangleShape shape;
  const double ab = (b - a).norm(), bc = (c - b).norm(), ca = (a - c).norm();
  shape.longest_side = std::max({ab, bc, ca});
  shape.perimeter = ab + bc + ca;
  // The cross product is stable for needle triangles where Heron's formula
  // cancels catastrophically.
  shape.area = 0.5 * (b - a).cross(c - a).norm();
  const double sum_of_squares = ab * ab + bc * bc + ca * ca;
  shape.compactness = sum_of_squares > 0 ? 4.0 * std::sqrt(3.0) * shape.area / sum_of_squares : 0;
  return shape;
}

/// Eq. 1 without the oversize case: P / (R C^2).
inline double baseCost(double perimeter, double shock_length, double compactness) {
  return perimeter / (shock_length * compactness * compactness);
}

/// f(theta) = (e^theta - 1)^2 - 1: -1 for a flat continuation, 0 near 39.7
/// degrees, large for folds.
inline double bendingPenalty(double bending_angle) {
  const double grown = std::exp(bending_angle) - 1.0;
  return grown * grown - 1.0;
}

/// Triangle (p, q, t) seen from its edge pq, for the bending angles of
/// several triangles (p, q, s) against it: what depends on s alone is left
/// to angleTo.
class BendingAcrossEdge {
public:
  BendingAcrossEdge(const Eigen::Vector3d &p, const Eigen::Vector3d &q, const Eigen::Vector3d &t)
      : p_(p), axis_(q - p), axis_squared_(axis_.squaredNorm()),
        to_t_(degenerate() ? Eigen::Vector3d::Zero() : across(t)) {}
  /// Whether p and q coincide: no bending is defined.
  bool degenerate() const { return axis_squared_ == 0; }
  /// The component of s - p perpendicular to the edge (not degenerate).
  Eigen::Vector3d across(const Eigen::Vector3d &s) const {
    return (s - p_) - axis_ * ((s - p_).dot(axis_) / axis_squared_);
  }
  /// across(t).
  const Eigen::Vector3d &acrossToT() const { return to_t_; }
  /// bendingAngle(p, q, t, s).
  double angleTo(const Eigen::Vector3d &s) const {
    if (degenerate())
      return M_PI;
    const Eigen::Vector3d to_s = across(s);
    // atan2 of |cross| and dot is accurate near 0 and pi, unlike acos.
    const double opening = std::atan2(to_t_.cross(to_s).norm(), to_t_.dot(to_s));
    return M_PI - opening;
  }

private:
  Eigen::Vector3d p_, axis_;
  double axis_squared_;
  Eigen::Vector3d to_t_;
};

/// Bending angle in [0, pi] between triangles (p, q, t) and (p, q, s) across
/// their shared edge pq: 0 when s continues the plane of t on the far side,
/// pi when the two triangles fold onto each other.
inline double bendingAngle(const Eigen::Vector3d &p, const Eigen::Vector3d &q,
                           const Eigen::Vector3d &t, const Eigen::Vector3d &s) {
  return BendingAcrossEdge(p, q, t).angleTo(s);
}

/// Whether bendingAngle(p, q, t, s) is surely below an angle under pi / 2
/// whose tangent squared is `limit_tan_squared`, without the arctangent:
/// where the opening is obtuse (dot < 0) the bending is atan(|cross| /
/// -dot), below the limit where cross^2 < limit_tan_squared dot^2. A margin
/// of 1e-6 of the limit stands far above the rounding of both ways; false
/// where this cannot tell, and bendingAngle() must.
inline bool bendsSurelyLessThan(const Eigen::Vector3d &p, const Eigen::Vector3d &q,
                                const Eigen::Vector3d &t, const Eigen::Vector3d &s,
                                double limit_tan_squared) {
  const BendingAcrossEdge edge(p, q, t);
  if (edge.degenerate())
    return false;
  const Eigen::Vector3d to_s = edge.across(s);
  const double dot = edge.acrossToT().dot(to_s);
  return dot < 0 &&
         edge.acrossToT().cross(to_s).squaredNorm() < (1 - 1e-6) * limit_tan_squared * dot * dot;
}

/// Eq. 2: context cost that accepted neighbour T adds to candidate S across
/// a shared edge of length d_i; inverse_shock_compactness = 1 / (R_S C_S^2).
inline double contextCost(double shared_edge_length, double inverse_shock_compactness,
                          double bending_angle) {
  return shared_edge_length * inverse_shock_compactness * bendingPenalty(bending_angle);
}

} // namespace pcl_ms
