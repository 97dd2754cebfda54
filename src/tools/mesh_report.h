// SPDX-License-Identifier: GPL-3.0-or-later
//
// The metrics of pcl_ms/mesh_quality.h as named rows, so that
// pcl_ms_compare and pcl_ms_evaluate print, tabulate and export the same
// quantities under the same names.
#pragma once

#include <pcl_ms/mesh_quality.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <vector>

namespace pcl_ms_tools {

struct Metric {
  enum class Kind {
    count,    // non-negative integer
    integer,  // signed integer
    fraction, // 0..1, shown as a percentage
    degrees,
    distance, // fraction of the reference's bounding-box diagonal, shown as a percentage
    length,   // absolute units
    flag,     // 0 or 1, shown as yes / no
    seconds,
    megabytes,
  };
  std::string key;   // machine name: CSV column, JSON member
  std::string label; // for people
  Kind kind = Kind::count;
  double value = 0;
  bool available = true; // false: no value (e.g. no reference given)
};

/// Every scalar of the topology report, in a fixed order.
std::vector<Metric> topologyMetrics(const pcl_ms::MeshTopologyReport &report);

/// Every scalar of the reference comparison, in a fixed order. Without a
/// report the same rows come back marked unavailable, so tables keep their
/// columns.
std::vector<Metric> referenceMetrics(const pcl_ms::ReferenceReport *report);

/// How many of `points` are vertices of a triangle of the mesh, matched by
/// position at single precision where that keeps each input's positions
/// apart, else bit for bit (position_keys.h): an interpolating mesh uses its
/// input points; Poisson's new vertices match none.
struct PointUsage {
  std::size_t points = 0;
  std::size_t used = 0;
  double fraction() const {
    return points == 0 ? 0.0 : static_cast<double>(used) / static_cast<double>(points);
  }
};
PointUsage pointsUsedAsVertices(const std::vector<Eigen::Vector3d> &points,
                                const std::vector<Eigen::Vector3d> &vertices,
                                const std::vector<pcl_ms::Triangle> &triangles);

std::vector<Metric> pointUsageMetrics(const PointUsage *usage);

/// For people: thousands separators, percentages, yes / no, "-" when unavailable.
std::string formatForPeople(const Metric &metric);
/// For files: full precision, "" when unavailable; infinities as "inf".
std::string formatForCsv(const Metric &metric);
/// A JSON value: numbers, true / false, null when unavailable or not finite.
std::string formatForJson(const Metric &metric);

/// Thousands separators: 69451 -> "69,451".
std::string withThousands(std::size_t value);
/// Quotes a CSV field when it needs it (RFC 4180).
std::string csvField(const std::string &text);
/// A JSON string literal with the needed escapes.
std::string jsonString(const std::string &text);

} // namespace pcl_ms_tools
