// SPDX-License-Identifier: GPL-3.0-or-later
// The core's single entry point: points in, triangles (user indices) out.
#pragma once

#include <pcl_ms/types.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace pcl_ms {

/// Thrown for input or parameters the method cannot work with; what() is a
/// one-line reason meant for the user.
class ReconstructionError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// Meshes the points. Invalid (NaN/Inf) records are skipped and exact
/// duplicates merged; output indices still refer to `points` records.
/// Throws ReconstructionError on unusable input (no or too few distinct
/// points, collinear points, invalid parameters).
Result reconstruct(const PointView &points, const Parameters &parameters);

/// Re-meshes around a partial mesh: `initial_triangles` (user record
/// indices, edge-manifold, each once) are in the surface from the start and
/// the method completes it around them. Throws ReconstructionError when an
/// initial triangle uses an invalid or missing point, repeats, is
/// degenerate, or a third triangle is put on an edge. Where they meet at a
/// vertex only and the surface does not join them, that vertex stays a
/// pinch. The one-piece path is used whatever the cloud's size.
Result reconstruct(const PointView &points, const Parameters &parameters,
                   const std::vector<Triangle> &initial_triangles);

class BucketExchange;

/// Meshes the points with several processes sharing the buckets and seam
/// zones (see BucketExchange in buckets.h). Every process calls it with the
/// same points and parameters; the triangles are the same as with one.
/// Process 0 gets the mesh; the others get the preparation's and the
/// buckets' figures and no triangles. A cloud meshed in one piece is meshed
/// by process 0 alone.
Result reconstruct(const PointView &points, const Parameters &parameters, BucketExchange &exchange);

} // namespace pcl_ms
