// SPDX-License-Identifier: GPL-3.0-or-later
#include "mesh_report.h"

#include "position_keys.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <unordered_set>

namespace pcl_ms_tools {

namespace {

using Kind = Metric::Kind;

Metric make(const char *key, const char *label, Kind kind, double value, bool available = true) {
  Metric metric;
  metric.key = key;
  metric.label = label;
  metric.kind = kind;
  metric.value = value;
  metric.available = available;
  return metric;
}

double count(std::size_t value) { return static_cast<double>(value); }

std::string printed(const char *format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

} // namespace

std::vector<Metric> topologyMetrics(const pcl_ms::MeshTopologyReport &r) {
  return {
      make("vertices", "vertices", Kind::count, count(r.vertices)),
      make("referenced_vertices", "vertices used by triangles", Kind::count,
           count(r.referenced_vertices)),
      make("used_vertex_fraction", "share of vertices used", Kind::fraction,
           r.used_vertex_fraction),
      make("triangles", "triangles", Kind::count, count(r.triangles)),
      make("invalid_triangles", "triangles with a missing vertex", Kind::count,
           count(r.invalid_triangles)),
      make("degenerate_triangles", "degenerate triangles", Kind::count,
           count(r.degenerate_triangles)),
      make("duplicate_triangles", "duplicate triangles", Kind::count, count(r.duplicate_triangles)),
      make("edges", "edges", Kind::count, count(r.edges)),
      make("boundary_edges", "boundary edges", Kind::count, count(r.boundary_edges)),
      make("non_manifold_edges", "non-manifold edges", Kind::count, count(r.non_manifold_edges)),
      make("non_manifold_vertices", "non-manifold vertices", Kind::count,
           count(r.non_manifold_vertices)),
      make("boundary_loops", "boundary loops", Kind::count, count(r.boundary_loops)),
      make("open_boundary_chains", "open boundary chains", Kind::count,
           count(r.open_boundary_chains)),
      make("largest_boundary_loop", "edges of the largest boundary loop", Kind::count,
           count(r.boundary_loop_lengths.empty() ? 0 : r.boundary_loop_lengths.front())),
      make("components", "components", Kind::count, count(r.components)),
      make("euler_characteristic", "Euler characteristic", Kind::integer,
           static_cast<double>(r.euler_characteristic)),
      make("orientable", "orientable", Kind::flag, r.orientable ? 1 : 0),
      make("non_orientable_components", "non-orientable components", Kind::count,
           count(r.non_orientable_components)),
      make("inconsistently_oriented_edges", "inconsistently oriented edges", Kind::count,
           count(r.inconsistently_oriented_edges)),
      make("median_min_angle_deg", "median smallest angle", Kind::degrees, r.median_min_angle_deg),
      make("share_min_angle_below_10deg", "triangles with an angle below 10 degrees",
           Kind::fraction, r.share_min_angle_below_10deg),
  };
}

std::vector<Metric> referenceMetrics(const pcl_ms::ReferenceReport *report) {
  const pcl_ms::ReferenceReport r = report ? *report : pcl_ms::ReferenceReport();
  const bool a = report != nullptr;
  return {
      make("reference_triangles", "reference triangles", Kind::count, count(r.reference_triangles),
           a),
      make("recovered_reference_triangles", "reference triangles recovered", Kind::count,
           count(r.recovered_reference_triangles), a),
      make("recall", "recall (reference triangles recovered)", Kind::fraction, r.recall, a),
      make("triangles_in_reference", "triangles that are reference triangles", Kind::count,
           count(r.triangles_in_reference), a),
      make("precision", "precision (triangles in the reference)", Kind::fraction, r.precision, a),
      make("to_reference_mean", "distance to reference, mean", Kind::distance, r.to_reference.mean,
           a),
      make("to_reference_p95", "distance to reference, 95th percentile", Kind::distance,
           r.to_reference.p95, a),
      make("to_reference_max", "distance to reference, max", Kind::distance, r.to_reference.max, a),
      make("from_reference_mean", "distance from reference, mean", Kind::distance,
           r.from_reference.mean, a),
      make("from_reference_p95", "distance from reference, 95th percentile", Kind::distance,
           r.from_reference.p95, a),
      make("from_reference_max", "distance from reference, max", Kind::distance,
           r.from_reference.max, a),
      make("hausdorff", "Hausdorff distance (larger max)", Kind::distance,
           std::max(r.to_reference.max, r.from_reference.max), a),
      make("fscore_0_1", "F-score at 0.1 % of the diagonal", Kind::fraction, r.fscore_0_1, a),
      make("fscore_0_5", "F-score at 0.5 % of the diagonal", Kind::fraction, r.fscore_0_5, a),
      make("reference_diagonal", "reference bounding-box diagonal", Kind::length,
           r.reference_diagonal, a),
  };
}

PointUsage pointsUsedAsVertices(const std::vector<Eigen::Vector3d> &points,
                                const std::vector<Eigen::Vector3d> &vertices,
                                const std::vector<pcl_ms::Triangle> &triangles) {
  using namespace pcl_ms::metrics_detail;
  const PositionPrecision precision = matchingPrecision(points, vertices);
  std::unordered_set<PositionKey, PositionKeyHash> used;
  for (const pcl_ms::Triangle &triangle : triangles)
    for (pcl_ms::VertexIndex v : triangle)
      if (v < vertices.size())
        used.insert(positionKey(vertices[v], precision));
  PointUsage usage;
  usage.points = points.size();
  for (const Eigen::Vector3d &p : points)
    usage.used += used.count(positionKey(p, precision));
  return usage;
}

std::vector<Metric> pointUsageMetrics(const PointUsage *usage) {
  const bool a = usage != nullptr;
  const PointUsage u = a ? *usage : PointUsage();
  return {
      make("input_points", "input points", Kind::count, count(u.points), a),
      make("input_points_used", "input points that are vertices", Kind::count, count(u.used), a),
      make("input_points_used_fraction", "share of input points that are vertices", Kind::fraction,
           u.fraction(), a),
  };
}

std::string withThousands(std::size_t value) {
  const std::string digits = std::to_string(value);
  std::string out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0)
      out += ',';
    out += digits[i];
  }
  return out;
}

std::string formatForPeople(const Metric &metric) {
  if (!metric.available)
    return "-";
  const double v = metric.value;
  if (std::isinf(v))
    return v > 0 ? "inf" : "-inf";
  if (std::isnan(v))
    return "nan";
  switch (metric.kind) {
  case Kind::count:
    return withThousands(static_cast<std::size_t>(v));
  case Kind::integer:
    return (v < 0 ? "-" : "") + withThousands(static_cast<std::size_t>(std::fabs(v)));
  case Kind::fraction:
    return printed("%.2f %%", 100 * v);
  case Kind::degrees:
    return printed("%.1f", v);
  case Kind::distance:
    return printed("%.3f %%", 100 * v);
  case Kind::length:
    return printed("%.6g", v);
  case Kind::flag:
    return v != 0 ? "yes" : "no";
  case Kind::seconds:
    return printed("%.3f", v);
  case Kind::megabytes:
    return printed("%.1f", v);
  }
  return "";
}

std::string formatForCsv(const Metric &metric) {
  if (!metric.available)
    return "";
  if (std::isinf(metric.value))
    return metric.value > 0 ? "inf" : "-inf";
  if (metric.kind == Kind::count || metric.kind == Kind::integer || metric.kind == Kind::flag)
    return printed("%.0f", metric.value);
  return printed("%.9g", metric.value);
}

std::string formatForJson(const Metric &metric) {
  if (!metric.available || !std::isfinite(metric.value))
    return "null";
  if (metric.kind == Kind::flag)
    return metric.value != 0 ? "true" : "false";
  return formatForCsv(metric);
}

std::string csvField(const std::string &text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos)
    return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"')
      quoted += '"';
    quoted += c;
  }
  return quoted + '"';
}

std::string jsonString(const std::string &text) {
  std::string out = "\"";
  for (unsigned char c : text) {
    switch (c) {
    case '"':
      out += "\\\"";
      break;
    case '\\':
      out += "\\\\";
      break;
    case '\n':
      out += "\\n";
      break;
    case '\t':
      out += "\\t";
      break;
    case '\r':
      out += "\\r";
      break;
    default:
      if (c < 0x20) {
        char escaped[8];
        std::snprintf(escaped, sizeof(escaped), "\\u%04x", static_cast<unsigned>(c));
        out += escaped;
      } else {
        out += static_cast<char>(c);
      }
    }
  }
  return out + "\"";
}

} // namespace pcl_ms_tools
