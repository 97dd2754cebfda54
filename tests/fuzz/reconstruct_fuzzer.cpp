// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for pcl_ms::reconstruct on small clouds built from the
// fuzzer's bytes in the shapes that trouble Delaunay-based methods: raw
// floats (NaN, Inf, denormals), grids, co-spherical points, duplicates and
// huge or tiny magnitudes, meshed in one piece or in buckets. A run must end
// with a 2-manifold mesh over valid records or a ReconstructionError.
#include "fuzz_clouds.h"

#include <pcl_ms/reconstruct.h>

#include <cstdint>
#include <vector>

namespace pcl_ms_fuzz {

/// The target's body (see PCL_MS_FUZZ_TARGET).
inline int reconstructOneInput(const std::uint8_t *data, std::size_t size) {
  ByteReader bytes(data, size);
  pcl_ms::Parameters parameters;
  const std::uint8_t options = bytes.byte();
  parameters.fill_holes_max_edges = (options & 1) ? 0 : 8;
  parameters.grid_buckets = (options & 2) ? 2 : 0; // buckets even for tiny clouds
  parameters.num_threads = (options & 4) ? 2 : 1;
  parameters.min_points_for_threads = 0; // the parallel loops on tiny clouds too
  parameters.error_recovery = (options & 8) == 0;
  parameters.rho = 1.0 + (options >> 4);
  const std::vector<float> xyz = buildCloud(bytes);

  pcl_ms::PointView view;
  view.xyz = xyz.data();
  view.size = xyz.size() / 3;
  pcl_ms::Result result;
  try {
    result = pcl_ms::reconstruct(view, parameters);
  } catch (const pcl_ms::ReconstructionError &) {
    return 0; // a clear error is an allowed outcome
  }
  checkMesh(xyz, {}, result, true);
  return 0;
}

} // namespace pcl_ms_fuzz

PCL_MS_FUZZ_TARGET(pcl_ms_fuzz::reconstructOneInput)
