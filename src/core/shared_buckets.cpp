// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 5 with the points spread over processes (docs/algorithm.md, "Across
// processes", "By owner, from slices"). In: each process's slice of the prepared
// points (its "home" points). Out: on process 0, the surface and the points
// that one process meshing the whole cloud in buckets (buckets.cpp) would
// have. No process holds the cloud while meshing: the tree is cut with
// exact selections across the processes, every point goes to the owner of
// its bucket and of the buckets whose margin it lies in, and each seam
// zone's owner receives the points of its slab and the corners of the
// triangles it keeps fixed from their homes.
#include <pcl_ms/finish.h>
#include <pcl_ms/prepared_points.h>
#include <pcl_ms/reconstruct.h>

#include "bucket_parts.h"
#include "cuts_in_parts.h"
#include "finish_in_parts.h"
#include "median_spacing.h"
#include "points_from_homes.h"
#include "process_bytes.h"
#include "shared_tree.h"
#include "sort_unique.h"
#include "threads.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <type_traits>
#include <unordered_map>

namespace pcl_ms {
namespace {

using detail::Box;
using detail::bytesOf;
using detail::countsOf;
using detail::deliver;
using detail::fromZeroToAll;
using detail::gatherAtZero;
using detail::totalOver;
using detail::valuesOf;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A prepared point's data as it travels to process 0.
struct JoinedPoint {
  std::array<double, 3> position;
  std::array<float, 3> normal;
  VertexIndex record;
};
static_assert(sizeof(JoinedPoint) == 40, "travels as bytes, without padding");

/// A point on its way to a process that needs it.
struct PointRecord {
  std::array<double, 3> position;
  std::array<float, 3> normal;
  float scale;        // its bucket's local scale; 0 until measured
  VertexIndex index;  // in the whole cloud's prepared order
  std::uint32_t leaf; // its bucket
};
static_assert(sizeof(PointRecord) == 48, "records travel as bytes, without padding");

/// A point with the unit (bucket or zone) that asked for it.
struct PointFor {
  PointRecord point;
  std::uint32_t unit, padding = 0;
};

/// A point by index, with the unit that asks for it (or 0).
struct IndexFor {
  VertexIndex index;
  std::uint32_t unit;
};

/// A point's local scale, on its way home.
struct ScaleFor {
  VertexIndex index;
  float scale;
};

/// A triangle of a subtree at a seam zone's points, to the zone's owner:
/// its segment's place in the whole list's order and its place in the segment.
struct FixedFor {
  Triangle triangle;
  std::uint32_t segment, index, unit;
};
static_assert(sizeof(FixedFor) == 24, "travels as bytes, without padding");

/// A triangle of the whole list, to the process whose run holds `place`.
struct PlacedTriangle {
  Triangle triangle;
  std::uint32_t padding = 0;
  std::uint64_t place;
};
static_assert(sizeof(PlacedTriangle) == 24, "travels as bytes, without padding");

using Node = detail::TreeNode;

/// The points of all processes in buckets and seam zones, by owner.
class SharedBuckets {
public:
  SharedBuckets(const PreparedSlice &slice, const Parameters &parameters, const Deadline *deadline,
                ProcessGroup &group, bool in_runs)
      : home_(slice.points), first_(slice.first), total_(slice.total), parameters_(parameters),
        deadline_(deadline), group_(group), in_runs_(in_runs && !parameters.compute_medial_axis),
        home_scale_(home_.positions.size(), 0.0f), home_pinch_(home_.positions.size(), 0) {
    home_first_ = detail::firstsOf(countsOf(home_.positions.size(), group_));
  }

  SharedSurface run() {
    buildTree();
    meshLeaves();
    for (int depth = tree_.max_depth; depth >= 0; --depth)
      stitchLevel(depth);
    return finish();
  }

private:
  // ---- the tree ----------------------------------------------------------------

  void buildTree() {
    tree_ = buildSharedTree(home_.positions, first_, parameters_, group_);
    // The whole list is the segments of the tree's nodes (a leaf's
    // triangles, an inner node's seam) in post-order: a node's subtree, then
    // its seam.
    segment_order_.assign(tree_.nodes.size(), 0);
    std::uint32_t next = 0;
    std::vector<std::pair<int, bool>> stack;
    if (tree_.root >= 0)
      stack.push_back({tree_.root, false});
    while (!stack.empty()) {
      const std::pair<int, bool> top = stack.back();
      stack.pop_back();
      const Node &node = tree_.nodes[static_cast<std::size_t>(top.first)];
      if (top.second || node.axis < 0) {
        segment_order_[static_cast<std::size_t>(top.first)] = next++;
        continue;
      }
      stack.push_back({top.first, true});
      stack.push_back({node.children[1], false});
      stack.push_back({node.children[0], false});
    }
    segment_count_ = next;
    statistics_.buckets = tree_.leaves.size();
    for (const Node &node : tree_.nodes)
      statistics_.seam_zones += node.axis >= 0;
  }

  VertexIndex globalIndex(std::size_t home) const {
    return static_cast<VertexIndex>(first_ + home);
  }

  int ownerOf(std::uint32_t leaf) const {
    return bucketOwner(leaf, tree_.leaves.size(), group_.processes());
  }

  int homeOf(VertexIndex index) const {
    return static_cast<int>(detail::runHolding(home_first_, index));
  }

  PointRecord homeRecord(std::size_t i) const {
    PointRecord record{};
    for (int a = 0; a < 3; ++a)
      record.position[a] = home_.positions[i][a];
    if (!home_.normals.empty())
      for (int a = 0; a < 3; ++a)
        record.normal[a] = home_.normals[i][a];
    record.scale = home_scale_[i];
    record.index = globalIndex(i);
    record.leaf = tree_.home_leaf[i];
    return record;
  }

  static Eigen::Vector3d positionOf(const PointRecord &record) {
    return Eigen::Vector3d(record.position[0], record.position[1], record.position[2]);
  }

  /// A unit's task from its points, ascending by index.
  BucketTask taskOf(const std::vector<PointRecord> &members) const {
    BucketTask task;
    task.points.reserve(members.size());
    for (const PointRecord &member : members)
      task.points.push_back(positionOf(member));
    if (parameters_.use_normals) {
      task.normals.reserve(members.size());
      for (const PointRecord &member : members)
        task.normals.emplace_back(member.normal[0], member.normal[1], member.normal[2]);
    }
    return task;
  }

  // ---- the buckets ---------------------------------------------------------------

  /// Calls visit(leaf) for every leaf whose margin box holds p.
  template <typename Visit> void leavesReaching(const Eigen::Vector3d &p, const Visit &visit) {
    std::vector<int> stack{tree_.root};
    while (!stack.empty()) {
      const int index = stack.back();
      stack.pop_back();
      const Node &node = tree_.nodes[static_cast<std::size_t>(index)];
      if (!node.region.expanded(subtree_margin_[static_cast<std::size_t>(index)]).contains(p))
        continue;
      if (node.axis < 0) {
        if (node.region.expanded(leaf_margin_[node.first_leaf]).contains(p))
          visit(node.first_leaf);
      } else {
        stack.push_back(node.children[0]);
        stack.push_back(node.children[1]);
      }
    }
  }

  /// Each bucket's spacing, as bucketSpacings in buckets.cpp.
  void measureMargins(const std::vector<std::vector<PointRecord>> &own) {
    std::vector<double> spacings(tree_.leaves.size(), 0.0);
    for (std::size_t k = 0; k < own.size(); ++k)
      spacings[own_leaves_[k]] =
          detail::medianSpacing(own[k].size(), detail::spacing_samples_per_bucket,
                                [&](std::size_t i) { return positionOf(own[k][i]); });
    group_.maximum(spacings);
    double fallback = *std::max_element(spacings.begin(), spacings.end());
    if (!(fallback > 0)) {
      // No bucket has two points (a few points in a fine grid): the
      // cloud's spacing, from all its points (few, then).
      std::vector<std::array<double, 3>> mine(home_.positions.size());
      for (std::size_t i = 0; i < mine.size(); ++i)
        mine[i] = {home_.positions[i][0], home_.positions[i][1], home_.positions[i][2]};
      const auto all = valuesOf<std::array<double, 3>>(group_.gatherAll(bytesOf(mine)));
      fallback =
          detail::medianSpacing(all.size(), detail::spacing_samples_per_bucket, [&](std::size_t i) {
            return Eigen::Vector3d(all[i][0], all[i][1], all[i][2]);
          });
    }
    leaf_margin_.resize(tree_.leaves.size());
    for (std::size_t leaf = 0; leaf < tree_.leaves.size(); ++leaf)
      leaf_margin_[leaf] =
          detail::bucketMargin(parameters_.rho, spacings[leaf] > 0 ? spacings[leaf] : fallback);
    subtree_margin_.assign(tree_.nodes.size(), 0.0);
    for (std::size_t n = 0; n < tree_.nodes.size(); ++n)
      subtree_margin_[n] = *std::max_element(leaf_margin_.begin() + tree_.nodes[n].first_leaf,
                                             leaf_margin_.begin() + tree_.nodes[n].end_leaf);
  }

  void meshLeaves() {
    const Clock::time_point stage = Clock::now();
    for (std::uint32_t leaf = 0; leaf < tree_.leaves.size(); ++leaf)
      if (ownerOf(leaf) == group_.process())
        own_leaves_.push_back(leaf);
    // Every point to the owner of its bucket.
    const auto processes = static_cast<std::size_t>(group_.processes());
    std::vector<std::vector<PointRecord>> outgoing(processes);
    for (std::size_t i = 0; i < home_.positions.size(); ++i)
      outgoing[static_cast<std::size_t>(ownerOf(tree_.home_leaf[i]))].push_back(homeRecord(i));
    std::vector<std::vector<PointRecord>> own(own_leaves_.size());
    deliver(outgoing, group_,
            [&](const PointRecord &record) { own[ownSlot(record.leaf)].push_back(record); });
    for (std::vector<PointRecord> &points : own)
      std::sort(points.begin(), points.end(),
                [](const PointRecord &a, const PointRecord &b) { return a.index < b.index; });
    measureMargins(own);
    // And to the owners of the buckets whose margin it lies in.
    std::vector<std::vector<PointFor>> margins(processes);
    for (std::size_t i = 0; i < home_.positions.size(); ++i)
      leavesReaching(home_.positions[i], [&](std::uint32_t leaf) {
        if (leaf != tree_.home_leaf[i])
          margins[static_cast<std::size_t>(ownerOf(leaf))].push_back({homeRecord(i), leaf});
      });
    std::vector<std::vector<PointRecord>> members = std::move(own);
    std::vector<std::size_t> margin_points(members.size(), 0);
    deliver(margins, group_, [&](const PointFor &arrived) {
      members[ownSlot(arrived.unit)].push_back(arrived.point);
      ++margin_points[ownSlot(arrived.unit)];
    });

    progress_ =
        std::make_unique<detail::ProgressReporter>(parameters_, own_leaves_.size() + ownZones());
    detail::ProgressReporter &progress = *progress_;
    std::vector<BucketOutcome> outcomes(own_leaves_.size());
    leaf_triangles_.resize(own_leaves_.size());
    // Per bucket: its core points' scales and the vertices that may pinch,
    // to go back to the points' homes.
    std::vector<std::vector<ScaleFor>> scales_of(own_leaves_.size());
    std::vector<std::vector<IndexFor>> pinches_of(own_leaves_.size());
    detail::withThreads(parameters_.num_threads, [&] {
      detail::parallelFor(
          tbb::blocked_range<std::size_t>(0, own_leaves_.size(), 1),
          [&](const tbb::blocked_range<std::size_t> &range) {
            for (std::size_t k = range.begin(); k != range.end(); ++k) {
              std::vector<PointRecord> &points = members[k];
              std::sort(
                  points.begin(), points.end(),
                  [](const PointRecord &a, const PointRecord &b) { return a.index < b.index; });
              BucketTask task = taskOf(points);
              task.core.resize(points.size());
              for (std::size_t i = 0; i < points.size(); ++i)
                task.core[i] = points[i].leaf == own_leaves_[k];
              BucketOutcome &outcome = outcomes[k];
              outcome = meshBucket(task, parameters_, deadline_);
              task = BucketTask();
              leaf_triangles_[k] = toGlobal(outcome.triangles, points);
              if (!outcome.local_scale.empty())
                for (std::size_t i = 0; i < points.size(); ++i)
                  if (points[i].leaf == own_leaves_[k])
                    scales_of[k].push_back({points[i].index, outcome.local_scale[i]});
              for (VertexIndex v : outcome.cut_vertices)
                pinches_of[k].push_back({points[v].index, 0});
              // Only the figures stay: the bucket's points and arrays go.
              std::vector<PointRecord>().swap(points);
              outcome.triangles = {};
              outcome.local_scale = {};
              outcome.cut_vertices = {};
              progress.unitDone();
            }
          });
    });
    std::vector<std::vector<ScaleFor>> scales(processes);
    std::vector<std::vector<IndexFor>> pinches(processes);
    for (std::size_t k = 0; k < own_leaves_.size(); ++k) {
      for (const ScaleFor &scale : scales_of[k])
        scales[static_cast<std::size_t>(homeOf(scale.index))].push_back(scale);
      for (const IndexFor &pinch : pinches_of[k])
        pinches[static_cast<std::size_t>(homeOf(pinch.index))].push_back(pinch);
      std::vector<ScaleFor>().swap(scales_of[k]);
      std::vector<IndexFor>().swap(pinches_of[k]);
    }
    deliver(scales, group_,
            [&](const ScaleFor &scale) { home_scale_[scale.index - first_] = scale.scale; });
    deliver(pinches, group_, [&](const IndexFor &pinch) { home_pinch_[pinch.index - first_] = 1; });

    // The buckets' figures: only the owner's entry is non-zero.
    std::vector<double> d_med(tree_.leaves.size(), 0.0), failed(tree_.leaves.size(), 0.0),
        margin(tree_.leaves.size(), 0.0);
    std::uint32_t first_failure = std::numeric_limits<std::uint32_t>::max();
    std::string first_error;
    for (std::size_t k = 0; k < own_leaves_.size(); ++k) {
      const BucketOutcome &outcome = outcomes[k];
      addTimings(outcome);
      d_med[own_leaves_[k]] = outcome.error.empty() ? outcome.d_med : 0.0;
      failed[own_leaves_[k]] = outcome.error.empty() ? 0.0 : 1.0;
      margin[own_leaves_[k]] = static_cast<double>(margin_points[k]);
      if (!outcome.error.empty() && first_error.empty()) {
        first_failure = own_leaves_[k];
        first_error = outcome.error;
      }
    }
    group_.maximum(d_med);
    group_.maximum(failed);
    group_.maximum(margin);
    std::vector<double> bucket_d_meds;
    for (std::size_t leaf = 0; leaf < tree_.leaves.size(); ++leaf) {
      statistics_.margin_points += static_cast<std::size_t>(margin[leaf]);
      if (failed[leaf] == 0.0)
        bucket_d_meds.push_back(d_med[leaf]);
      else
        ++statistics_.failed_units;
    }
    if (bucket_d_meds.empty()) {
      // Every process throws the error of the first bucket, as one would.
      std::vector<double> first{static_cast<double>(first_failure)};
      group_.minimum(first);
      std::vector<unsigned char> mine;
      if (first_failure == static_cast<std::uint32_t>(first[0]))
        mine.assign(first_error.begin(), first_error.end());
      const std::vector<unsigned char> all = group_.gatherAll(mine);
      detail::throwNoBucketMeshed(std::string(all.begin(), all.end()));
    }
    d_med_ = detail::medianBucketDMed(std::move(bucket_d_meds));
    statistics_.buckets_seconds = secondsSince(stage);
  }

  std::size_t ownSlot(std::uint32_t leaf) const {
    return static_cast<std::size_t>(std::lower_bound(own_leaves_.begin(), own_leaves_.end(), leaf) -
                                    own_leaves_.begin());
  }

  static std::vector<Triangle> toGlobal(const std::vector<Triangle> &local,
                                        const std::vector<PointRecord> &members) {
    std::vector<Triangle> global(local.size());
    for (std::size_t t = 0; t < local.size(); ++t)
      for (int k = 0; k < 3; ++k)
        global[t][k] = members[local[t][k]].index;
    return global;
  }

  std::size_t ownZones() const {
    std::size_t zones = 0;
    for (const Node &node : tree_.nodes)
      zones += node.axis >= 0 && ownerOf(node.first_leaf) == group_.process();
    return zones;
  }

  void addTimings(const BucketOutcome &outcome) {
    timings_[0] += outcome.delaunay_seconds;
    timings_[1] += outcome.scaffold_seconds;
    timings_[2] += outcome.greedy_seconds;
  }

  // ---- the seams -----------------------------------------------------------------

  /// Calls visit(i) for every home point i inside `box`. Home points are in
  /// Morton order, so runs of them are compact: runs whose bounding box
  /// misses `box` are skipped whole.
  template <typename Visit> void forEachHomeIn(const Box &box, const Visit &visit) {
    constexpr std::size_t run = 256;
    if (run_boxes_.empty())
      for (std::size_t begin = 0; begin < home_.positions.size(); begin += run) {
        Box bounds;
        bounds.low = bounds.high = home_.positions[begin];
        for (std::size_t i = begin; i < std::min(home_.positions.size(), begin + run); ++i) {
          bounds.low = bounds.low.cwiseMin(home_.positions[i]);
          bounds.high = bounds.high.cwiseMax(home_.positions[i]);
        }
        run_boxes_.push_back(bounds);
      }
    for (std::size_t r = 0; r < run_boxes_.size(); ++r)
      if (run_boxes_[r].intersects(box))
        for (std::size_t i = r * run; i < std::min(home_.positions.size(), (r + 1) * run); ++i)
          if (box.contains(home_.positions[i]))
            visit(i);
  }

  void stitchLevel(int depth) {
    const Clock::time_point stage = Clock::now();
    if (depth == tree_.max_depth) {
      // The buckets' triangles become their leaves' sets.
      for (std::size_t k = 0; k < own_leaves_.size(); ++k)
        node_triangles_[tree_.leaves[own_leaves_[k]]] = std::move(leaf_triangles_[k]);
      std::vector<std::vector<Triangle>>().swap(leaf_triangles_);
    }
    std::vector<int> level;
    for (std::size_t n = 0; n < tree_.nodes.size(); ++n)
      if (tree_.nodes[n].axis >= 0 && tree_.nodes[n].depth == depth)
        level.push_back(static_cast<int>(n));
    const auto processes = static_cast<std::size_t>(group_.processes());
    const int me = group_.process();
    auto zoneOwner = [&](int node) {
      return ownerOf(tree_.nodes[static_cast<std::size_t>(node)].first_leaf);
    };

    // The largest local scale near each plane and those points' bounds,
    // from every home.
    std::vector<double> margin(level.size()), largest(level.size(), 0.0);
    std::vector<double> low(3 * level.size()), high(3 * level.size());
    std::vector<Box> near_planes;
    for (std::size_t z = 0; z < level.size(); ++z) {
      const Node &node = tree_.nodes[static_cast<std::size_t>(level[z])];
      margin[z] = subtree_margin_[static_cast<std::size_t>(level[z])];
      near_planes.push_back(
          detail::zoneSlab(node.region, node.axis, node.split, margin[z], margin[z]));
      float scale = 0;
      Box bounds = detail::emptyBox();
      forEachHomeIn(near_planes.back(), [&](std::size_t i) {
        scale = std::max(scale, home_scale_[i]);
        bounds.extend(home_.positions[i]);
      });
      largest[z] = scale;
      for (int a = 0; a < 3; ++a) {
        low[3 * z + a] = bounds.low[a];
        high[3 * z + a] = bounds.high[a];
      }
    }
    group_.maximum(largest);
    group_.minimum(low);
    group_.maximum(high);

    // How far each zone reaches, tile by tile along its plane, from every
    // home's scales near the plane (as in one process: ZoneReach).
    std::vector<detail::ZoneReach> reaches;
    std::vector<Box> slabs;
    std::vector<double> tile_scales;
    for (std::size_t z = 0; z < level.size(); ++z) {
      const Node &node = tree_.nodes[static_cast<std::size_t>(level[z])];
      const auto largest_scale = static_cast<float>(largest[z]);
      Box bounds;
      for (int a = 0; a < 3; ++a) {
        bounds.low[a] = low[3 * z + a];
        bounds.high[a] = high[3 * z + a];
      }
      slabs.push_back(detail::zoneSlab(node.region, node.axis, node.split, margin[z],
                                       parameters_.rho * largest_scale));
      reaches.emplace_back(bounds, node.axis, node.split, parameters_.rho, largest_scale);
      forEachHomeIn(near_planes[z], [&](std::size_t i) {
        reaches.back().addScale(home_.positions[i], home_scale_[i]);
      });
      const std::vector<float> &scales = reaches.back().tileScales();
      tile_scales.insert(tile_scales.end(), scales.begin(), scales.end());
    }
    group_.maximum(tile_scales);
    {
      std::size_t next = 0;
      for (detail::ZoneReach &reach : reaches)
        for (float &scale : reach.tileScales())
          scale = static_cast<float>(tile_scales[next++]);
    }

    // Each zone's points, from their homes, to its owner.
    std::vector<std::vector<PointFor>> outgoing(processes);
    for (std::size_t z = 0; z < level.size(); ++z) {
      forEachHomeIn(slabs[z], [&](std::size_t i) {
        if (reaches[z].reaches(home_.positions[i]))
          outgoing[static_cast<std::size_t>(zoneOwner(level[z]))].push_back(
              {homeRecord(i), static_cast<std::uint32_t>(z)});
      });
    }
    std::vector<std::vector<PointRecord>> zone_points(level.size());
    deliver(outgoing, group_,
            [&](const PointFor &arrived) { zone_points[arrived.unit].push_back(arrived.point); });

    // Each zone's point numbers, from its owner, to the processes holding
    // triangles of its subtree (the owners of its leaves), which send back
    // those at the zone's points: the triangles the zone keeps fixed. The
    // triangles stay on the processes that made them.
    std::vector<std::vector<VertexIndex>> zone_indices(level.size());
    std::vector<std::vector<FixedFor>> fixed_parts(level.size());
    {
      std::vector<std::vector<IndexFor>> zone_out(processes);
      for (std::size_t z = 0; z < level.size(); ++z) {
        if (zoneOwner(level[z]) != me)
          continue;
        std::vector<PointRecord> &points = zone_points[z];
        std::sort(points.begin(), points.end(),
                  [](const PointRecord &a, const PointRecord &b) { return a.index < b.index; });
        for (const PointRecord &point : points)
          zone_indices[z].push_back(point.index);
        const Node &node = tree_.nodes[static_cast<std::size_t>(level[z])];
        int holder = -1;
        for (std::uint32_t leaf = node.first_leaf; leaf < node.end_leaf; ++leaf)
          if (ownerOf(leaf) != holder) { // the leaves' owners ascend
            holder = ownerOf(leaf);
            for (VertexIndex v : zone_indices[z])
              zone_out[static_cast<std::size_t>(holder)].push_back(
                  {v, static_cast<std::uint32_t>(z)});
          }
      }
      std::vector<std::vector<VertexIndex>> asked(level.size());
      deliver(zone_out, group_, [&](const IndexFor &one) { asked[one.unit].push_back(one.index); });
      std::vector<std::vector<FixedFor>> fixed_out(processes);
      for (std::size_t z = 0; z < level.size(); ++z) {
        if (asked[z].empty())
          continue;
        const Node &node = tree_.nodes[static_cast<std::size_t>(level[z])];
        const auto owner = static_cast<std::size_t>(zoneOwner(level[z]));
        auto atZone = [&](VertexIndex v) {
          return std::binary_search(asked[z].begin(), asked[z].end(), v);
        };
        for (const auto &held : node_triangles_) {
          const Node &segment = tree_.nodes[static_cast<std::size_t>(held.first)];
          if (held.first == level[z] || segment.first_leaf < node.first_leaf ||
              segment.end_leaf > node.end_leaf)
            continue;
          const std::vector<Triangle> &triangles = held.second;
          for (std::size_t i = 0; i < triangles.size(); ++i)
            if (atZone(triangles[i][0]) || atZone(triangles[i][1]) || atZone(triangles[i][2]))
              fixed_out[owner].push_back(
                  {triangles[i], segment_order_[static_cast<std::size_t>(held.first)],
                   static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(z)});
        }
      }
      deliver(fixed_out, group_,
              [&](const FixedFor &one) { fixed_parts[one.unit].push_back(one); });
    }

    // The fixed triangles' corners outside the zone, from their homes.
    std::vector<std::vector<IndexFor>> requests(processes);
    std::vector<std::vector<Triangle>> fixed(level.size());
    for (std::size_t z = 0; z < level.size(); ++z) {
      if (zoneOwner(level[z]) != me)
        continue;
      auto inZone = [&](VertexIndex v) {
        return std::binary_search(zone_indices[z].begin(), zone_indices[z].end(), v);
      };
      // In the order of the subtree's list: its segments in the tree's order.
      std::vector<FixedFor> &parts = fixed_parts[z];
      std::sort(parts.begin(), parts.end(), [](const FixedFor &a, const FixedFor &b) {
        return a.segment < b.segment || (a.segment == b.segment && a.index < b.index);
      });
      std::vector<VertexIndex> frozen;
      for (const FixedFor &part : parts) {
        fixed[z].push_back(part.triangle);
        for (VertexIndex v : part.triangle)
          if (!inZone(v))
            frozen.push_back(v);
      }
      std::vector<FixedFor>().swap(parts);
      detail::sortUnique(frozen);
      for (VertexIndex v : frozen)
        requests[static_cast<std::size_t>(homeOf(v))].push_back({v, static_cast<std::uint32_t>(z)});
    }
    // Answered in the order asked: each home returns a record per request.
    std::vector<std::vector<IndexFor>> asked(processes);
    {
      std::vector<std::vector<unsigned char>> bytes(processes);
      for (std::size_t p = 0; p < processes; ++p)
        bytes[p] = bytesOf(requests[p]);
      // Who asked what: exchange returns requests in process order; sizes
      // per process follow from the counts every process sent everyone.
      std::vector<std::uint64_t> sent(processes * processes, 0);
      for (std::size_t p = 0; p < processes; ++p)
        sent[static_cast<std::size_t>(me) * processes + p] = requests[p].size();
      group_.sum(sent);
      const std::vector<IndexFor> all = valuesOf<IndexFor>(group_.exchange(bytes));
      std::size_t next = 0;
      for (std::size_t p = 0; p < processes; ++p) {
        const std::size_t count = sent[p * processes + static_cast<std::size_t>(me)];
        asked[p].assign(all.begin() + static_cast<std::ptrdiff_t>(next),
                        all.begin() + static_cast<std::ptrdiff_t>(next + count));
        next += count;
      }
    }
    std::vector<std::vector<PointFor>> answers(processes);
    for (std::size_t p = 0; p < processes; ++p)
      for (const IndexFor &request : asked[p])
        answers[p].push_back({homeRecord(request.index - first_), request.unit});
    std::vector<std::vector<PointRecord>> frozen_points(level.size());
    deliver(answers, group_,
            [&](const PointFor &answer) { frozen_points[answer.unit].push_back(answer.point); });

    // The zones this process owns, meshed as one process meshes them.
    std::vector<std::size_t> mine;
    for (std::size_t z = 0; z < level.size(); ++z)
      if (zoneOwner(level[z]) == me)
        mine.push_back(z);
    std::vector<BucketOutcome> outcomes(mine.size());
    std::vector<std::vector<PointRecord>> members(mine.size());
    std::vector<std::vector<bool>> core(mine.size());
    std::vector<std::size_t> core_points(mine.size(), 0);
    detail::withThreads(parameters_.num_threads, [&] {
      detail::parallelFor(tbb::blocked_range<std::size_t>(0, mine.size(), 1),
                          [&](const tbb::blocked_range<std::size_t> &range) {
                            for (std::size_t k = range.begin(); k != range.end(); ++k)
                              outcomes[k] = stitch(level[mine[k]], zone_points[mine[k]],
                                                   frozen_points[mine[k]], fixed[mine[k]],
                                                   members[k], core[k], core_points[k]);
                          });
    });
    std::vector<std::vector<IndexFor>> pinches(processes);
    for (std::size_t k = 0; k < mine.size(); ++k) {
      const int node = level[mine[k]];
      const BucketOutcome &outcome = outcomes[k];
      addTimings(outcome);
      std::vector<Triangle> added;
      if (core_points[k] >= 3) {
        added = toGlobal(outcome.triangles, members[k]);
        for (VertexIndex v : outcome.cut_vertices)
          pinches[static_cast<std::size_t>(homeOf(members[k][v].index))].push_back(
              {members[k][v].index, 0});
        for (std::size_t i = 0; i < members[k].size(); ++i)
          if (core[k][i])
            pinches[static_cast<std::size_t>(homeOf(members[k][i].index))].push_back(
                {members[k][i].index, 0});
        seam_figures_[2] += outcome.error.empty() ? 0.0 : 1.0;
      }
      seam_figures_[0] += static_cast<double>(core_points[k]);
      seam_figures_[1] += static_cast<double>(outcome.triangles.size());
      // The seam's segment of the whole list, after its subtree's.
      if (!added.empty())
        node_triangles_[node] = std::move(added);
      progress_->unitDone();
    }
    deliver(pinches, group_, [&](const IndexFor &pinch) { home_pinch_[pinch.index - first_] = 1; });
    statistics_.seams_seconds += secondsSince(stage);
    if (deadline_)
      deadline_->check("the seams");
  }

  /// One zone (buckets.cpp, planZone and stitch): its points within reach of
  /// the plane, core when in the node's subtree, and the fixed triangles'
  /// corners outside it, frozen.
  BucketOutcome stitch(int node_index, const std::vector<PointRecord> &zone,
                       std::vector<PointRecord> &frozen, const std::vector<Triangle> &fixed,
                       std::vector<PointRecord> &members, std::vector<bool> &core,
                       std::size_t &core_points) const {
    const Node &node = tree_.nodes[static_cast<std::size_t>(node_index)];
    auto inSubtree = [&](const PointRecord &point) {
      return point.leaf >= node.first_leaf && point.leaf < node.end_leaf;
    };
    for (const PointRecord &point : zone)
      core_points += inSubtree(point);
    BucketOutcome outcome;
    if (core_points < 3) {
      outcome.error = "too few points";
      return outcome;
    }
    auto byIndex = [](const PointRecord &a, const PointRecord &b) { return a.index < b.index; };
    std::sort(frozen.begin(), frozen.end(), byIndex);
    members.reserve(zone.size() + frozen.size());
    std::merge(zone.begin(), zone.end(), frozen.begin(), frozen.end(), std::back_inserter(members),
               byIndex);
    BucketTask task = taskOf(members);
    // No d_med, as in buckets.cpp: a point without a scale takes the zone's.
    task.local_scale.reserve(members.size());
    for (const PointRecord &member : members)
      task.local_scale.push_back(member.scale);
    task.core.resize(members.size());
    task.frozen.resize(members.size());
    for (std::size_t i = 0; i < members.size(); ++i) {
      const bool is_frozen = std::binary_search(frozen.begin(), frozen.end(), members[i], byIndex);
      task.frozen[i] = is_frozen;
      task.core[i] = !is_frozen && inSubtree(members[i]);
    }
    core = task.core;
    auto localIndex = [&](VertexIndex v) {
      return static_cast<VertexIndex>(
          std::lower_bound(members.begin(), members.end(), v,
                           [](const PointRecord &a, VertexIndex b) { return a.index < b; }) -
          members.begin());
    };
    task.fixed_triangles.reserve(fixed.size());
    for (const Triangle &triangle : fixed)
      task.fixed_triangles.push_back(
          {localIndex(triangle[0]), localIndex(triangle[1]), localIndex(triangle[2])});
    return meshBucket(task, parameters_, deadline_);
  }

  // ---- the end: the list in runs, split, finished, then to process 0 ---------

  SharedSurface finish() {
    std::vector<double> figures{seam_figures_[0], seam_figures_[1], seam_figures_[2],
                                timings_[0],      timings_[1],      timings_[2]};
    std::vector<std::uint64_t> sums(figures.size());
    // Counts are whole; seconds are summed in microseconds.
    for (std::size_t f = 0; f < figures.size(); ++f)
      sums[f] = static_cast<std::uint64_t>(std::llround(f < 3 ? figures[f] : figures[f] * 1e6));
    group_.sum(sums);
    statistics_.seam_points = sums[0];
    statistics_.seam_triangles = sums[1];
    statistics_.failed_units += sums[2];

    SharedSurface shared;
    BucketedSurface &surface = shared.surface;
    surface.d_med = d_med_;
    surface.delaunay_seconds = static_cast<double>(sums[3]) * 1e-6;
    surface.scaffold_seconds = static_cast<double>(sums[4]) * 1e-6;
    surface.greedy_seconds = static_cast<double>(sums[5]) * 1e-6;

    const Clock::time_point stage = Clock::now();
    std::uint64_t first = 0;
    std::vector<Triangle> run = wholeListInRuns(first);
    // The bow-ties the seams may have made, at the seams' points (as
    // meshInBuckets splits them).
    std::vector<VertexIndex> pinches;
    for (std::size_t i = 0; i < home_pinch_.size(); ++i)
      if (home_pinch_[i])
        pinches.push_back(globalIndex(i));
    std::vector<std::uint8_t>().swap(home_pinch_);
    detail::CutPart split = detail::cutInParts(run, first, {}, group_, pinches);
    std::vector<Triangle>().swap(run);
    statistics_.bow_tie_triangles_removed = split.split_off;
    surface.statistics = statistics_;
    if (deadline_)
      deadline_->check("the bow-tie split");

    // Where no bucket measured a point's scale, the cloud's spacing stands in.
    std::vector<float> scales(home_scale_);
    for (float &scale : scales)
      if (!(scale > 0))
        scale = static_cast<float>(d_med_);
    Eigen::Vector3d viewpoint;
    if (parameters_.viewpoint)
      viewpoint = Eigen::Vector3d((*parameters_.viewpoint)[0], (*parameters_.viewpoint)[1],
                                  (*parameters_.viewpoint)[2]) -
                  home_.centre;
    detail::FinishedPart part = detail::finishInParts(
        split.kept, split.first, home_.positions, scales, first_, parameters_.fill_holes_max_edges,
        parameters_.rho, parameters_.viewpoint ? &viewpoint : nullptr, group_);
    split = detail::CutPart();
    std::vector<float>().swap(scales);
    shared.finish_seconds = secondsSince(stage);
    if (deadline_)
      deadline_->check("the finish");
    if (in_runs_)
      keepFinishedInRuns(part, shared);
    else
      gatherFinished(part, shared);
    return shared;
  }

  /// The segments of the whole list, from the processes that made them, in
  /// runs of equal length following each other in process order; `first`
  /// is this process's run's first number.
  std::vector<Triangle> wholeListInRuns(std::uint64_t &first) {
    std::vector<std::uint64_t> segment_first(segment_count_ + 1, 0);
    for (const auto &held : node_triangles_)
      segment_first[segment_order_[static_cast<std::size_t>(held.first)] + 1] = held.second.size();
    group_.sum(segment_first);
    for (std::size_t s = 1; s < segment_first.size(); ++s)
      segment_first[s] += segment_first[s - 1];
    const std::uint64_t total = segment_first.back();
    const auto processes = static_cast<std::uint64_t>(group_.processes());
    std::vector<std::uint64_t> run_first(processes + 1);
    for (std::uint64_t p = 0; p <= processes; ++p)
      run_first[p] = total * p / processes;
    const auto me = static_cast<std::size_t>(group_.process());
    first = run_first[me];
    std::vector<std::vector<PlacedTriangle>> outgoing(processes);
    for (auto &held : node_triangles_) {
      std::uint64_t place = segment_first[segment_order_[static_cast<std::size_t>(held.first)]];
      for (const Triangle &triangle : held.second) {
        outgoing[detail::runHolding(run_first, place)].push_back({triangle, 0, place});
        ++place;
      }
      std::vector<Triangle>().swap(held.second);
    }
    std::unordered_map<int, std::vector<Triangle>>().swap(node_triangles_);
    std::vector<Triangle> run(static_cast<std::size_t>(run_first[me + 1] - first));
    deliver(outgoing, group_, [&](const PlacedTriangle &arrived) {
      run[static_cast<std::size_t>(arrived.place - first)] = arrived.triangle;
    });
    return run;
  }

  /// Every component's first triangle, with whether it is orientable.
  struct ComponentStart {
    std::uint64_t first;
    std::uint64_t orientable;
  };

  /// Every process gets every component's start, in list order; process 0's
  /// `finished` its figures, loops and components' orientability.
  std::vector<ComponentStart> componentStarts(detail::FinishedPart &part,
                                              FinishedSurface &finished) {
    finished.holes_filled = part.holes_filled;
    finished.twist_triangles_removed = part.twist_triangles_removed;
    finished.boundary_loops = std::move(part.boundary_loops);
    std::vector<ComponentStart> starts, mine;
    for (std::size_t t = 0; t < part.triangles.size(); ++t)
      if (part.component[t] == part.first + t)
        mine.push_back({part.component[t], part.orientable[t]});
    const std::uint64_t components = totalOver(mine.size(), group_);
    if (group_.process() == 0)
      starts.resize(components);
    gatherAtZero<ComponentStart>(
        mine.size(), [&](std::size_t i) { return mine[i]; },
        [&](std::size_t c, const ComponentStart &start) { starts[c] = start; }, group_);
    fromZeroToAll(starts, group_);
    if (group_.process() == 0)
      for (const ComponentStart &start : starts)
        finished.component_orientable.push_back(start.orientable != 0);
    return starts;
  }

  /// The number, among `starts`, of the component that starts at `first`.
  static std::uint32_t componentNumber(const std::vector<ComponentStart> &starts,
                                       std::uint64_t first) {
    const auto at =
        std::lower_bound(starts.begin(), starts.end(), first,
                         [](const ComponentStart &a, std::uint64_t b) { return a.first < b; });
    return static_cast<std::uint32_t>(at - starts.begin());
  }

  /// Collective. Every point number that forEachVertex(visit) visits (a
  /// VertexIndex &) becomes its point's record in the user's cloud, asked
  /// once from the point's home.
  template <typename ForEachVertex> void toUserRecords(const ForEachVertex &forEachVertex) {
    std::vector<VertexIndex> vertices;
    forEachVertex([&](VertexIndex &v) { vertices.push_back(v); });
    detail::sortUnique(vertices);
    const std::vector<VertexIndex> records = detail::valuesFromHomes<VertexIndex>(
        vertices, home_first_, first_, [&](std::size_t i) { return home_.user_index[i]; }, group_);
    forEachVertex([&](VertexIndex &v) {
      v = records[static_cast<std::size_t>(std::lower_bound(vertices.begin(), vertices.end(), v) -
                                           vertices.begin())];
    });
  }

  /// Every process keeps its run of the finished surface, in the user's
  /// records with its components' numbers; process 0 gets the loops in the
  /// user's records and the figures.
  void keepFinishedInRuns(detail::FinishedPart &part, SharedSurface &shared) {
    const std::vector<ComponentStart> starts = componentStarts(part, shared.finished);
    FinishedRun &run = shared.run;
    run.used = true;
    run.first = part.first;
    run.total = totalOver(part.triangles.size(), group_);
    run.component.resize(part.triangles.size());
    for (std::size_t t = 0; t < part.triangles.size(); ++t)
      run.component[t] = componentNumber(starts, part.component[t]);
    // Not held while the corners are looked up.
    std::vector<std::uint64_t>().swap(part.component);
    std::vector<std::uint8_t>().swap(part.orientable);
    run.triangles = std::move(part.triangles);
    // The corners become the user's records a piece of the run at a time:
    // the lookups stay small beside the run.
    constexpr std::size_t piece = std::size_t(1) << 20;
    const std::size_t size = run.triangles.size();
    const std::uint64_t pieces = detail::maximumOver((size + piece - 1) / piece, group_);
    for (std::uint64_t k = 0; k < pieces; ++k) {
      const std::size_t begin = std::min<std::size_t>(size, k * piece);
      const std::size_t end = std::min(size, begin + piece);
      toUserRecords([&](const auto &visit) {
        for (std::size_t t = begin; t < end; ++t)
          for (VertexIndex &v : run.triangles[t])
            visit(v);
      });
    }
    part = detail::FinishedPart();
    // The loops are on process 0 only.
    toUserRecords([&](const auto &visit) {
      for (auto &loop : shared.finished.boundary_loops)
        for (VertexIndex &v : loop)
          visit(v);
    });
  }

  /// Process 0 gets the finished surface: the triangles, their components
  /// numbered in the order of their first triangles, the loops, the
  /// figures, and every point's record in the user's cloud.
  void gatherFinished(detail::FinishedPart &part, SharedSurface &shared) {
    FinishedSurface &finished = shared.finished;
    const std::vector<ComponentStart> starts = componentStarts(part, finished);
    struct NumberedTriangle {
      Triangle corners;
      std::uint32_t component;
    };
    const bool zero = group_.process() == 0;
    const std::uint64_t total = totalOver(part.triangles.size(), group_);
    if (zero) {
      finished.triangles.resize(total);
      finished.triangle_component.resize(total);
    }
    gatherAtZero<NumberedTriangle>(
        part.triangles.size(),
        [&](std::size_t t) {
          return NumberedTriangle{part.triangles[t], componentNumber(starts, part.component[t])};
        },
        [&](std::size_t t, const NumberedTriangle &triangle) {
          finished.triangles[t] = triangle.corners;
          finished.triangle_component[t] = triangle.component;
        },
        group_);
    part = detail::FinishedPart();
    // The points' records; their positions only for the medial axis.
    shared.points.centre = home_.centre;
    if (parameters_.compute_medial_axis) {
      shared.points = joinSlicesAtProcessZero(home_, false, group_);
      return;
    }
    if (zero)
      shared.points.user_index.resize(total_);
    gatherAtZero<VertexIndex>(
        home_.user_index.size(), [&](std::size_t i) { return home_.user_index[i]; },
        [&](std::size_t v, VertexIndex record) { shared.points.user_index[v] = record; }, group_);
  }

  const PreparedPoints &home_;
  const std::size_t first_, total_;
  const Parameters &parameters_;
  const Deadline *deadline_;
  ProcessGroup &group_;
  const bool in_runs_;                    // the finished surface stays in runs (no medial axis)
  std::vector<std::uint64_t> home_first_; // process p's home points start at home_first_[p]
  std::vector<float> home_scale_;
  std::vector<std::uint8_t> home_pinch_;

  SharedTree tree_;
  std::vector<double> leaf_margin_, subtree_margin_;
  std::vector<Box> run_boxes_; // of runs of home points (forEachHomeIn)

  std::vector<std::uint32_t> own_leaves_; // ascending
  std::vector<std::vector<Triangle>> leaf_triangles_;
  /// The segments of the whole list this process made, by node.
  std::unordered_map<int, std::vector<Triangle>> node_triangles_;
  std::vector<std::uint32_t> segment_order_; // by node
  std::uint32_t segment_count_ = 0;
  std::unique_ptr<detail::ProgressReporter> progress_;
  double d_med_ = 0;
  BucketStatistics statistics_;
  double timings_[3] = {0, 0, 0};
  double seam_figures_[3] = {0, 0, 0};
};

} // namespace

PreparedPoints joinSlicesAtProcessZero(const PreparedPoints &slice, bool with_normals,
                                       ProcessGroup &group) {
  const std::uint64_t total = totalOver(slice.positions.size(), group);
  PreparedPoints joined;
  joined.centre = slice.centre;
  if (group.process() == 0) {
    joined.positions.resize(total);
    joined.user_index.resize(total);
    if (with_normals)
      joined.normals.resize(total);
  }
  gatherAtZero<JoinedPoint>(
      slice.positions.size(),
      [&](std::size_t i) {
        JoinedPoint point{};
        point.position = {slice.positions[i][0], slice.positions[i][1], slice.positions[i][2]};
        if (with_normals)
          point.normal = {slice.normals[i][0], slice.normals[i][1], slice.normals[i][2]};
        point.record = slice.user_index[i];
        return point;
      },
      [&](std::size_t v, const JoinedPoint &point) {
        joined.positions[v] =
            Eigen::Vector3d(point.position[0], point.position[1], point.position[2]);
        joined.user_index[v] = point.record;
        if (with_normals)
          joined.normals[v] = Eigen::Vector3f(point.normal[0], point.normal[1], point.normal[2]);
      },
      group);
  return joined;
}

SharedSurface meshSlicesInBuckets(const PreparedSlice &slice, const Parameters &parameters,
                                  const Deadline *deadline, ProcessGroup &group, bool in_runs) {
  return SharedBuckets(slice, parameters, deadline, group, in_runs).run();
}

} // namespace pcl_ms
