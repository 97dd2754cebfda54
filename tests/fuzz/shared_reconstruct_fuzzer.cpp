// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the shared path (docs/algorithm.md, "Across
// processes"): a small degenerate cloud from the fuzzer's bytes, cut into
// 1 to 4 parts at the fuzzer's places (parts may be empty), prepared and
// meshed by threads standing in for processes (preparePointsTogether,
// reconstructSlices) must give what one process gives: the same triangles
// and loops, or on every process the same ReconstructionError.
#include "core/thread_processes.h"
#include "fuzz_clouds.h"

#include <pcl_ms/prepared_points.h>
#include <pcl_ms/reconstruct.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace pcl_ms_fuzz {

/// The target's body (see PCL_MS_FUZZ_TARGET).
inline int sharedReconstructOneInput(const std::uint8_t *data, std::size_t size) {
  ByteReader bytes(data, size);
  pcl_ms::Parameters parameters;
  const std::uint8_t options = bytes.byte();
  const int processes = 1 + (options & 3);
  parameters.grid_buckets = (options & 4) ? 2 + ((options >> 3) & 1) : 0;
  parameters.fill_holes_max_edges = (options & 16) ? 0 : 8;
  parameters.num_threads = (options & 32) ? 2 : 1;
  parameters.min_points_for_threads = 0; // the parallel loops on tiny clouds too
  std::vector<std::uint8_t> cut_bytes;
  for (int p = 1; p < processes; ++p)
    cut_bytes.push_back(bytes.byte());
  const std::vector<float> xyz = buildCloud(bytes);
  const std::size_t records = xyz.size() / 3;

  pcl_ms::PointView view;
  view.xyz = xyz.data();
  view.size = records;
  pcl_ms::Result one;
  std::string one_error;
  try {
    one = pcl_ms::reconstruct(view, parameters);
  } catch (const pcl_ms::ReconstructionError &error) {
    one_error = error.what();
  }

  std::vector<std::size_t> cuts{0};
  for (std::uint8_t cut : cut_bytes)
    cuts.push_back(records * cut / 255);
  std::sort(cuts.begin(), cuts.end());
  cuts.push_back(records);
  std::vector<pcl_ms::Result> results(static_cast<std::size_t>(processes));
  std::vector<std::string> errors(static_cast<std::size_t>(processes));
  pcl_ms_test::onThreadProcesses(processes, [&](pcl_ms::ProcessGroup &group) {
    const auto p = static_cast<std::size_t>(group.process());
    pcl_ms::PointView part;
    part.size = cuts[p + 1] - cuts[p];
    part.xyz = part.size > 0 ? xyz.data() + 3 * cuts[p] : nullptr;
    try {
      results[p] = pcl_ms::reconstructSlices(
          pcl_ms::preparePointsTogether(part, cuts[p], false, group), parameters, group);
    } catch (const pcl_ms::ReconstructionError &error) {
      errors[p] = error.what();
    }
  });
  // Process 0 meshes a cloud in one piece and finishes every surface, so it
  // alone may fail where the others went on.
  if (errors[0] != one_error)
    broken("process 0 failed otherwise than one process");
  for (std::size_t p = 1; p < errors.size(); ++p)
    if (!errors[p].empty() && errors[p] != one_error)
      broken("a process failed otherwise than one process");
  if (!one_error.empty())
    return 0;
  if (results[0].triangles != one.triangles)
    broken("the processes' triangles are not one process's");
  if (results[0].boundary_loops != one.boundary_loops)
    broken("the processes' boundary loops are not one process's");
  if (results[0].duplicate_points != one.duplicate_points ||
      results[0].invalid_points != one.invalid_points || results[0].far_points != one.far_points)
    broken("the processes counted the records otherwise than one process");
  return 0;
}

} // namespace pcl_ms_fuzz

PCL_MS_FUZZ_TARGET(pcl_ms_fuzz::sharedReconstructOneInput)
