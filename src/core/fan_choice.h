// SPDX-License-Identifier: GPL-3.0-or-later
// Which fan stays at a bow-tie (docs/algorithm.md section 4, "Bow-ties"):
// the one rule of the greedy's manifold sweep and of the bow-tie split that
// finishing and the buckets share. In: a weight per fan. Out: the fan to keep.
// Internal: not installed.
#pragma once

#include <cstddef>
#include <tuple>

namespace pcl_ms {
namespace detail {

/// What decides between the fans at a vertex. The split after the greedy
/// knows only the sizes: the other fields stay 0 there.
struct FanWeight {
  std::size_t fixed = 0;     // triangles the caller fixed
  std::size_t preferred = 0; // triangles of a preferred initial mesh
  std::size_t size = 0;      // triangles
  double cost = 0;           // sum of the triangles' greedy costs
};

/// Whether fan a ranks before fan b: more fixed triangles, then more
/// preferred ones, then more triangles, then the cheaper.
inline bool ranksBefore(const FanWeight &a, const FanWeight &b) {
  return std::make_tuple(b.fixed, b.preferred, b.size, a.cost) <
         std::make_tuple(a.fixed, a.preferred, a.size, b.cost);
}

/// The fan to keep among fan_count fans: the first that no other ranks
/// before. weigh(f) gives fan f's weight.
template <typename Weigh> std::size_t fanToKeep(std::size_t fan_count, const Weigh &weigh) {
  std::size_t keep = 0;
  FanWeight best = weigh(0);
  for (std::size_t f = 1; f < fan_count; ++f) {
    const FanWeight weight = weigh(f);
    if (ranksBefore(weight, best)) {
      keep = f;
      best = weight;
    }
  }
  return keep;
}

} // namespace detail
} // namespace pcl_ms
