// SPDX-License-Identifier: GPL-3.0-or-later
// Vertex positions as hash keys, for the metrics that match vertices of two
// meshes (or a mesh and a cloud) by position, and for pcl_ms_reconstruct's
// -initial mesh, matched to the cloud's points. The points every method meshes
// are PCL's floats, but a reference read from text (.off, .obj) and a mesh
// written as 9-digit text come back as doubles that are not those floats:
// compared bit for bit they never match. So positions are compared rounded
// to float, unless rounding would make two distinct positions of one input
// one (double-precision data far from the origin), and then bit for bit.
// Internal.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

namespace pcl_ms {
namespace metrics_detail {

/// The precision at which positions are compared.
enum class PositionPrecision { single, exact };

/// A position's coordinates as bits, rounded to float for `single`; -0 counts
/// as +0.
struct PositionKey {
  std::array<std::uint64_t, 3> bits{};
  bool operator==(const PositionKey &other) const { return bits == other.bits; }
};

inline PositionKey positionKey(const Eigen::Vector3d &point, PositionPrecision precision) {
  PositionKey key;
  for (int axis = 0; axis < 3; ++axis) {
    if (precision == PositionPrecision::single) {
      const float value = static_cast<float>(point[axis]) + 0.0f;
      std::uint32_t bits;
      std::memcpy(&bits, &value, sizeof value);
      key.bits[axis] = bits;
    } else {
      const double value = point[axis] + 0.0;
      std::memcpy(&key.bits[axis], &value, sizeof value);
    }
  }
  return key;
}

/// The finaliser of MurmurHash3: every input bit moves every output bit.
inline std::uint64_t mixBits(std::uint64_t value) {
  value ^= value >> 33;
  value *= 0xff51afd7ed558ccdULL;
  value ^= value >> 33;
  value *= 0xc4ceb9fe1a85ec53ULL;
  value ^= value >> 33;
  return value;
}

struct PositionKeyHash {
  std::size_t operator()(const PositionKey &key) const {
    return static_cast<std::size_t>(
        mixBits(key.bits[0] ^ mixBits(key.bits[1] ^ mixBits(key.bits[2]))));
  }
};

/// Whether rounding to float leaves the distinct positions among `positions`
/// distinct (non-finite ones are left out: no metric matches them). Sorted
/// as 16-byte records, float coordinates and index, to spare the memory of
/// full keys on meshes of millions of vertices.
inline bool roundingKeepsApart(const std::vector<Eigen::Vector3d> &positions) {
  struct Rounded {
    std::array<std::uint32_t, 3> bits;
    std::uint32_t index;
  };
  std::vector<Rounded> rounded;
  rounded.reserve(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i)
    if (positions[i].allFinite()) {
      const PositionKey key = positionKey(positions[i], PositionPrecision::single);
      rounded.push_back(
          {{static_cast<std::uint32_t>(key.bits[0]), static_cast<std::uint32_t>(key.bits[1]),
            static_cast<std::uint32_t>(key.bits[2])},
           static_cast<std::uint32_t>(i)});
    }
  std::sort(rounded.begin(), rounded.end(),
            [](const Rounded &a, const Rounded &b) { return a.bits < b.bits; });
  for (std::size_t i = 1; i < rounded.size(); ++i)
    if (rounded[i].bits == rounded[i - 1].bits &&
        !(positionKey(positions[rounded[i].index], PositionPrecision::exact) ==
          positionKey(positions[rounded[i - 1].index], PositionPrecision::exact)))
      return false;
  return true;
}

/// Single precision when it keeps the positions of both inputs apart.
inline PositionPrecision matchingPrecision(const std::vector<Eigen::Vector3d> &first,
                                           const std::vector<Eigen::Vector3d> &second) {
  return roundingKeepsApart(first) && roundingKeepsApart(second) ? PositionPrecision::single
                                                                 : PositionPrecision::exact;
}

} // namespace metrics_detail
} // namespace pcl_ms
