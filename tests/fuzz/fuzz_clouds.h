// SPDX-License-Identifier: GPL-3.0-or-later
// What the reconstruct fuzz targets share: small clouds built from the
// fuzzer's bytes in the shapes that trouble Delaunay-based methods, and the
// promises every reconstruct() result keeps.
#pragma once

#include "fuzz_bytes.h"

#include <pcl_ms/mesh_quality.h>
#include <pcl_ms/reconstruct.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace pcl_ms_fuzz {

inline constexpr std::size_t max_points = 96;

inline void addPoint(std::vector<float> &xyz, float x, float y, float z) {
  if (xyz.size() < 3 * max_points)
    xyz.insert(xyz.end(), {x, y, z});
}

inline std::vector<float> buildCloud(ByteReader &bytes) {
  std::vector<float> xyz;
  const int shape = bytes.byte() % 5;
  if (shape == 0) { // raw floats: every bit pattern, NaN and Inf included
    while (!bytes.empty())
      addPoint(xyz, bytes.rawFloat(), bytes.rawFloat(), bytes.rawFloat());
  } else if (shape == 1) { // a regular grid, possibly flat or a line
    const int nx = 1 + bytes.byte() % 5, ny = 1 + bytes.byte() % 5, nz = 1 + bytes.byte() % 4;
    const float step = std::ldexp(1.0f, static_cast<int>(bytes.byte() % 64) - 32);
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < ny; ++j)
        for (int k = 0; k < nz; ++k)
          addPoint(xyz, i * step, j * step, k * step);
  } else if (shape == 2) { // on one sphere: co-spherical within float rounding
    const float radius = std::ldexp(1.0f, static_cast<int>(bytes.byte() % 80) - 40);
    while (!bytes.empty()) {
      const float theta = bytes.byte() * 0.0246f, phi = bytes.byte() * 0.0123f;
      addPoint(xyz, radius * std::sin(phi) * std::cos(theta),
               radius * std::sin(phi) * std::sin(theta), radius * std::cos(phi));
    }
  } else if (shape == 3) { // a few points, each repeated
    std::vector<float> base;
    const int count = 1 + bytes.byte() % 8;
    for (int i = 0; i < 3 * count; ++i)
      base.push_back(bytes.unit());
    while (!bytes.empty()) {
      const int i = bytes.byte() % count;
      addPoint(xyz, base[3 * i], base[3 * i + 1], base[3 * i + 2]);
    }
  } else { // small coordinates times wildly different powers of two
    while (!bytes.empty()) {
      const float scale = std::ldexp(1.0f, static_cast<int>(bytes.byte() % 250) - 125);
      addPoint(xyz, bytes.unit() * scale, bytes.unit() * scale, bytes.unit() * scale);
    }
  }
  return xyz;
}

/// The promises every reconstruct() result keeps: triangles over valid
/// records of the cloud (among `allowed` when not empty), each once, and,
/// when `manifold`, a 2-manifold. Returns the mesh's topology.
inline pcl_ms::MeshTopologyReport checkMesh(const std::vector<float> &xyz,
                                            const std::vector<bool> &allowed,
                                            const pcl_ms::Result &result, bool manifold) {
  const std::size_t records = xyz.size() / 3;
  std::vector<Eigen::Vector3d> positions;
  for (std::size_t i = 0; i < records; ++i)
    positions.emplace_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  for (const pcl_ms::Triangle &triangle : result.triangles)
    for (pcl_ms::VertexIndex v : triangle)
      if (v >= records || !positions[v].allFinite() || (!allowed.empty() && !allowed[v]))
        broken("triangles use valid records only");
  const pcl_ms::MeshTopologyReport report = pcl_ms::analyzeMesh(positions, result.triangles);
  if (manifold && (report.non_manifold_edges != 0 || report.non_manifold_vertices != 0))
    broken("the mesh is a 2-manifold");
  if (report.duplicate_triangles != 0)
    broken("no triangle appears twice");
  return report;
}

} // namespace pcl_ms_fuzz
