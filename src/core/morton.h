// SPDX-License-Identifier: GPL-3.0-or-later
// Morton (Z-curve) codes, shared by the stages that put points in spatial
// order. Internal to the library: not installed.
#pragma once

#include <cstdint>

namespace pcl_ms {
namespace detail {

/// Interleaves the low 21 bits of x, y and z: points whose quantised
/// coordinates are close get close codes.
inline std::uint64_t mortonCode(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  auto spread = [](std::uint64_t value) {
    value &= 0x1fffff;
    value = (value | value << 32) & 0x1f00000000ffffULL;
    value = (value | value << 16) & 0x1f0000ff0000ffULL;
    value = (value | value << 8) & 0x100f00f00f00f00fULL;
    value = (value | value << 4) & 0x10c30c30c30c30c3ULL;
    value = (value | value << 2) & 0x1249249249249249ULL;
    return value;
  };
  return spread(x) | spread(y) << 1 | spread(z) << 2;
}

} // namespace detail
} // namespace pcl_ms
