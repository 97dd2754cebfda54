// SPDX-License-Identifier: GPL-3.0-or-later
// The core's single entry point: points in, triangles (user indices) out.
#pragma once

#include <pcl_ms/types.h>

#include <stdexcept>
#include <string>

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

} // namespace pcl_ms
