// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 1 with the cloud's records spread over processes (docs/algorithm.md,
// "Across processes"). In: each process's consecutive records. Out: each
// process's slice of the points one process would have prepared, in its
// order. The steps are those of reconstruct.cpp's preparePoints; what needs
// the whole cloud (selections, the far points' neighbours, the sort, the
// duplicates across slices) is done collectively.
#include <pcl_ms/prepared_points.h>
#include <pcl_ms/reconstruct.h>

#include "far_points.h"
#include "point_keys.h"
#include "process_bytes.h"
#include "threads.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

namespace pcl_ms {
namespace {

using detail::bytesOf;
using detail::countsOf;
using detail::maximumOver;
using detail::totalOver;
using detail::valuesOf;

// ---- exact selection across processes ---------------------------------------

/// Orders floats as integers: negative below positive, -0 as +0 (a
/// selection must not depend on which zero it meets first).
std::uint32_t orderKey(float value) {
  if (value == 0)
    value = 0.0f;
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return bits & 0x80000000u ? ~bits : bits | 0x80000000u;
}

float fromOrderKey(std::uint32_t key) {
  const std::uint32_t bits = key & 0x80000000u ? key & 0x7fffffffu : ~key;
  float value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

/// One selection: the value of rank `rank` (from 0) among the coordinates
/// on `axis` of all processes' points.
struct Selection {
  int axis = 0;
  std::uint64_t rank = 0;
};

/// The selected values, exact: a radix selection on the values' order keys,
/// a byte a round (4 rounds of 256-bin histograms summed over the
/// processes), each round among the values whose higher bytes match the
/// bytes chosen so far.
/// `excluded` (may be empty) leaves points out.
std::vector<double> selectTogether(const std::vector<Eigen::Vector3f> &points,
                                   const std::vector<bool> &excluded,
                                   const std::vector<Selection> &selections, ProcessGroup &group) {
  // Small histograms: a tiny cloud pays for what it sends, not for bins.
  constexpr int digit_bits = 8, rounds = 32 / digit_bits;
  constexpr std::size_t bins = std::size_t{1} << digit_bits;
  const std::size_t count = selections.size();
  std::vector<std::uint64_t> remaining(count);
  for (std::size_t q = 0; q < count; ++q)
    remaining[q] = selections[q].rank;
  std::vector<std::uint32_t> key(count, 0); // the digits chosen so far
  for (int round = 0; round < rounds; ++round) {
    const int shift = 32 - digit_bits * (round + 1);
    // The digits above this round's, to match in the key chosen so far.
    const std::uint32_t chosen_mask = round == 0 ? 0u : ~std::uint32_t{0} << (shift + digit_bits);
    std::vector<std::uint64_t> histogram(count * bins, 0);
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!excluded.empty() && excluded[i])
        continue;
      for (std::size_t q = 0; q < count; ++q) {
        const std::uint32_t k = orderKey(points[i][selections[q].axis]);
        if ((k & chosen_mask) == key[q])
          ++histogram[q * bins + ((k >> shift) & (bins - 1))];
      }
    }
    group.sum(histogram);
    for (std::size_t q = 0; q < count; ++q) {
      std::size_t bin = 0;
      while (bin + 1 < bins && histogram[q * bins + bin] <= remaining[q])
        remaining[q] -= histogram[q * bins + bin++];
      key[q] |= static_cast<std::uint32_t>(bin) << shift;
    }
  }
  std::vector<double> values(count);
  for (std::size_t q = 0; q < count; ++q)
    values[q] = detail::selectedValue(fromOrderKey(key[q]));
  return values;
}

// ---- far points (far_points.cpp, across processes) ---------------------------

struct FarOutcome {
  std::vector<bool> is_far;
  std::size_t count = 0; // over all processes
  Eigen::Vector3d low = Eigen::Vector3d::Zero(), high = Eigen::Vector3d::Zero();
  Eigen::Vector3d median = Eigen::Vector3d::Zero();
};

FarOutcome findFarPointsTogether(const std::vector<Eigen::Vector3f> &points, ProcessGroup &group) {
  FarOutcome far;
  far.is_far.assign(points.size(), false);
  const std::uint64_t n = totalOver(points.size(), group);
  if (n == 0)
    return far;
  const std::uint64_t tail = detail::tailRank(n);
  std::vector<Selection> box;
  for (int axis = 0; axis < 3; ++axis) {
    box.push_back({axis, tail});
    box.push_back({axis, n - 1 - tail});
  }
  const std::vector<double> sides = selectTogether(points, {}, box, group);
  const Eigen::Vector3d central_low(sides[0], sides[2], sides[4]);
  const Eigen::Vector3d central_high(sides[1], sides[3], sides[5]);
  const double size = (central_high - central_low).norm();

  // Every process judges all points outside the box (few), the same way.
  std::vector<std::size_t> outside;
  std::vector<std::array<float, 3>> outside_points;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (detail::outsideCentralBox(points[i], central_low, central_high, size)) {
      outside.push_back(i);
      outside_points.push_back({points[i].x(), points[i].y(), points[i].z()});
    }
  const std::vector<std::uint64_t> outside_counts = countsOf(outside.size(), group);
  std::uint64_t my_first = 0;
  for (int p = 0; p < group.process(); ++p)
    my_first += outside_counts[static_cast<std::size_t>(p)];
  std::vector<Eigen::Vector3f> all_outside;
  for (const auto &p : valuesOf<std::array<float, 3>>(group.gatherAll(bytesOf(outside_points))))
    all_outside.emplace_back(p[0], p[1], p[2]);
  const std::vector<bool> isolated =
      detail::isolatedOutside(std::move(all_outside), central_low, central_high, size);
  for (std::size_t k = 0; k < outside.size(); ++k)
    if (isolated[my_first + k]) {
      far.is_far[outside[k]] = true;
      ++far.count;
    }
  far.count = totalOver(far.count, group);

  const std::uint64_t kept = n - far.count;
  const std::vector<double> median =
      selectTogether(points, far.is_far, {{0, kept / 2}, {1, kept / 2}, {2, kept / 2}}, group);
  far.median = Eigen::Vector3d(median[0], median[1], median[2]);
  std::vector<double> low(3, std::numeric_limits<double>::infinity());
  std::vector<double> high(3, -std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!far.is_far[i])
      for (int axis = 0; axis < 3; ++axis) {
        low[axis] = std::min(low[axis], static_cast<double>(points[i][axis]));
        high[axis] = std::max(high[axis], static_cast<double>(points[i][axis]));
      }
  group.minimum(low);
  group.maximum(high);
  far.low = Eigen::Vector3d(low[0], low[1], low[2]);
  far.high = Eigen::Vector3d(high[0], high[1], high[2]);
  return far;
}

// ---- the sort across processes ------------------------------------------------

/// A record on its way to its place: its key and, when asked for, its normal.
struct KeyedNormal {
  detail::PointKey key;
  std::array<float, 3> normal;
  std::uint32_t padding = 0; // travels as bytes: none left unset
};
static_assert(sizeof(KeyedNormal) == 40, "travels as bytes, without unset padding");

const detail::PointKey &keyOf(const detail::PointKey &item) { return item; }
const detail::PointKey &keyOf(const KeyedNormal &item) { return item.key; }

/// Sorts the items of all processes by key (a sample sort): afterwards each
/// process holds a consecutive run of the one order, in process order.
template <typename Item>
std::vector<Item> sortTogether(std::vector<Item> items, ProcessGroup &group) {
  const auto byKey = [](const Item &a, const Item &b) { return keyOf(a) < keyOf(b); };
  detail::parallelSort(items.begin(), items.end(), byKey);
  const auto processes = static_cast<std::size_t>(group.processes());
  if (processes == 1)
    return items;
  // Regular samples of every process's sorted items choose the splitters;
  // keys are distinct, so any splitters give the same order, only the
  // balance depends on them.
  const std::size_t samples_each = 16 * processes;
  std::vector<detail::PointKey> samples;
  for (std::size_t s = 0; s < samples_each && !items.empty(); ++s)
    samples.push_back(keyOf(items[s * items.size() / samples_each]));
  std::vector<detail::PointKey> all_samples =
      valuesOf<detail::PointKey>(group.gatherAll(bytesOf(samples.data(), samples.size())));
  std::sort(all_samples.begin(), all_samples.end());
  std::vector<std::vector<unsigned char>> outgoing(processes);
  std::size_t begin = 0;
  for (std::size_t p = 0; p < processes; ++p) {
    std::size_t end = items.size();
    if (p + 1 < processes && !all_samples.empty()) {
      const detail::PointKey &splitter = all_samples[(p + 1) * all_samples.size() / processes];
      end = static_cast<std::size_t>(
          std::lower_bound(
              items.begin() + static_cast<std::ptrdiff_t>(begin), items.end(), splitter,
              [](const Item &item, const detail::PointKey &key) { return keyOf(item) < key; }) -
          items.begin());
    }
    outgoing[p] = bytesOf(items.data() + begin, end - begin);
    begin = end;
  }
  std::vector<Item>().swap(items);
  std::vector<Item> mine = valuesOf<Item>(group.exchange(outgoing));
  outgoing.clear();
  detail::parallelSort(mine.begin(), mine.end(), byKey); // runs from each process, each sorted
  return mine;
}

/// The last coordinates of a process's sorted run, if it has any.
struct RunEnd {
  std::uint32_t has = 0;
  std::array<float, 3> coordinates{};
};

/// The slice from the sorted run: duplicates merged onto the earliest record
/// (a run's first item may repeat the last of an earlier process's run).
template <typename Item>
PreparedSlice sliceOf(const std::vector<Item> &run, const Eigen::Vector3d &centre,
                      bool with_normals, ProcessGroup &group) {
  RunEnd mine;
  if (!run.empty()) {
    mine.has = 1;
    mine.coordinates = keyOf(run.back()).coordinates;
  }
  const std::vector<RunEnd> ends = valuesOf<RunEnd>(group.gatherAll(bytesOf(&mine, 1)));
  const RunEnd *before = nullptr;
  for (int p = 0; p < group.process(); ++p)
    if (ends[static_cast<std::size_t>(p)].has)
      before = &ends[static_cast<std::size_t>(p)];

  PreparedSlice slice;
  PreparedPoints &points = slice.points;
  points.centre = centre;
  std::size_t duplicates = 0;
  for (std::size_t i = 0; i < run.size(); ++i) {
    const detail::PointKey &key = keyOf(run[i]);
    const bool repeats = i > 0 ? key.coordinates == keyOf(run[i - 1]).coordinates
                               : before && key.coordinates == before->coordinates;
    if (repeats) {
      ++duplicates;
      continue;
    }
    points.positions.push_back(
        Eigen::Vector3d(key.coordinates[0], key.coordinates[1], key.coordinates[2]) - centre);
    points.user_index.push_back(key.record);
    if constexpr (std::is_same_v<Item, KeyedNormal>)
      if (with_normals)
        points.normals.push_back(detail::unitNormalOrZero(run[i].normal.data()));
  }
  const std::vector<std::uint64_t> distinct = countsOf(points.positions.size(), group);
  for (int p = 0; p < group.process(); ++p)
    slice.first += distinct[static_cast<std::size_t>(p)];
  for (std::uint64_t d : distinct)
    slice.total += d;
  slice.counts.duplicate_points = totalOver(duplicates, group);
  return slice;
}

} // namespace

PreparedSlice preparePointsTogether(const PointView &part, std::uint64_t first_record,
                                    bool with_normals, ProcessGroup &group) {
  // Checked together, so that every process throws, not just the one with
  // the fault (the others would wait for it).
  const char *const problems[] = {nullptr, "a part of a shared cloud takes no indices",
                                  "the point array is null",
                                  "normals were requested but none were given"};
  const std::uint64_t problem = maximumOver(part.indices                                     ? 1
                                            : part.size > 0 && !part.xyz                     ? 2
                                            : with_normals && part.size > 0 && !part.normals ? 3
                                                                                             : 0,
                                            group);
  if (problem > 0)
    throw ReconstructionError(problems[problem]);
  const std::uint64_t records = totalOver(part.size, group);
  const std::uint64_t end_record = maximumOver(first_record + part.size, group);
  if (std::max(records, end_record) >= std::numeric_limits<VertexIndex>::max())
    throw ReconstructionError("too many points for 32-bit indices");

  std::vector<std::size_t> finite;
  std::vector<Eigen::Vector3f> points;
  for (std::size_t i = 0; i < part.size; ++i) {
    const float *p = detail::recordAt(part.xyz, part.stride, i);
    if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])) {
      finite.push_back(i);
      points.emplace_back(p[0], p[1], p[2]);
    }
  }
  PreparationCounts counts;
  counts.input_points = records;
  counts.invalid_points = records - totalOver(finite.size(), group);

  // Far stray points stay out, as in one process.
  const FarOutcome far = findFarPointsTogether(points, group);
  counts.far_points = far.count;
  const detail::MortonCells cells(far.low, far.high);
  auto keyAt = [&](std::size_t k) {
    return cells.key(points[k].data(), static_cast<VertexIndex>(first_record + finite[k]));
  };

  PreparedSlice slice;
  if (with_normals) {
    std::vector<KeyedNormal> items;
    for (std::size_t k = 0; k < points.size(); ++k)
      if (!far.is_far[k]) {
        const float *n = detail::recordAt(part.normals, part.normal_stride, finite[k]);
        items.push_back({keyAt(k), {n[0], n[1], n[2]}});
      }
    std::vector<Eigen::Vector3f>().swap(points);
    slice = sliceOf(sortTogether(std::move(items), group), far.median, true, group);
  } else {
    std::vector<detail::PointKey> items;
    for (std::size_t k = 0; k < points.size(); ++k)
      if (!far.is_far[k])
        items.push_back(keyAt(k));
    std::vector<Eigen::Vector3f>().swap(points);
    slice = sliceOf(sortTogether(std::move(items), group), far.median, false, group);
  }
  counts.duplicate_points = slice.counts.duplicate_points;
  slice.counts = counts;
  if (slice.total < 3)
    throw ReconstructionError(tooFewPoints(counts, slice.total));
  return slice;
}

} // namespace pcl_ms
