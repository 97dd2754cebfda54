// SPDX-License-Identifier: GPL-3.0-or-later
// Large clouds in buckets (docs/algorithm.md section 5). In: distinct points.
// Out: the triangles of every bucket and seam zone, stitched, before
// finishing; each unit runs stages 2 and 3 (meshBucket).
#include <pcl_ms/buckets.h>
#include <pcl_ms/finish.h>
#include <pcl_ms/mesh_points.h>
#include <pcl_ms/reconstruct.h>

#include "bucket_parts.h"
#include "median_spacing.h"
#include "sort_unique.h"
#include "threads.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>

namespace pcl_ms {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

using detail::Box;

/// A node of the bucket tree, with what one process keeps in it.
struct Node : detail::TreeNode {
  std::vector<VertexIndex> points; // leaves: their points, ascending
  std::vector<Triangle> triangles; // kept so far in this subtree
};

class BucketTree {
public:
  BucketTree(const std::vector<Eigen::Vector3d> &points, std::size_t bucket_points, int grid)
      : points_(points), leaf_of_(points.size(), 0) {
    std::vector<VertexIndex> order(points.size());
    std::iota(order.begin(), order.end(), 0);
    if (grid > 0) {
      Eigen::Vector3d low = points[0], high = points[0];
      for (const Eigen::Vector3d &p : points) {
        low = low.cwiseMin(p);
        high = high.cwiseMax(p);
      }
      grid_low_ = low;
      grid_cell_ = ((high - low) / grid).cwiseMax(Eigen::Vector3d::Constant(1e-300));
      root_ = buildGrid(order, 0, order.size(), Box(), {0, 0, 0}, {grid, grid, grid}, 0);
    } else {
      root_ = buildMedian(order, 0, order.size(), Box(), bucket_points, 0);
    }
    fillLeaves(order);
    numberLeaves(root_);
  }

  int root() const { return root_; }
  std::vector<Node> &nodes() { return nodes_; }
  const std::vector<int> &leaves() const { return leaves_; }
  std::uint32_t leafOf(VertexIndex v) const { return leaf_of_[v]; }
  bool inSubtree(VertexIndex v, const Node &node) const {
    return leaf_of_[v] >= node.first_leaf && leaf_of_[v] < node.end_leaf;
  }

  /// Points inside `box`, ascending.
  std::vector<VertexIndex> gather(const Box &box) const {
    std::vector<VertexIndex> found;
    std::vector<int> stack{root_};
    while (!stack.empty()) {
      const Node &node = nodes_[stack.back()];
      stack.pop_back();
      if (!node.region.intersects(box))
        continue;
      if (node.axis < 0) {
        for (VertexIndex v : node.points)
          if (box.contains(points_[v]))
            found.push_back(v);
      } else {
        for (int child : node.children)
          if (child >= 0)
            stack.push_back(child);
      }
    }
    std::sort(found.begin(), found.end());
    return found;
  }

private:
  /// A leaf over order[begin, end); fillLeaves gives it its points.
  int makeLeaf(std::size_t begin, std::size_t end, const Box &region, int depth) {
    Node node;
    node.region = region;
    node.depth = depth;
    nodes_.push_back(std::move(node));
    leaf_ranges_.push_back({static_cast<int>(nodes_.size() - 1), begin, end});
    return static_cast<int>(nodes_.size() - 1);
  }

  /// Each leaf's points, ascending: one pass over the points in index order
  /// instead of a sort per leaf.
  void fillLeaves(const std::vector<VertexIndex> &order) {
    std::vector<int> leaf_node(points_.size(), -1);
    for (const LeafRange &range : leaf_ranges_) {
      nodes_[static_cast<std::size_t>(range.node)].points.reserve(range.end - range.begin);
      for (std::size_t i = range.begin; i < range.end; ++i)
        leaf_node[order[i]] = range.node;
    }
    for (VertexIndex v = 0; v < points_.size(); ++v)
      if (leaf_node[v] >= 0)
        nodes_[static_cast<std::size_t>(leaf_node[v])].points.push_back(v);
    leaf_ranges_ = {};
  }

  int makeInner(const Box &region, int axis, double split, int depth, int left, int right) {
    return detail::addInner(nodes_, region, axis, split, depth, left, right);
  }

  /// Splits at the median of the longest side until buckets are small enough.
  int buildMedian(std::vector<VertexIndex> &order, std::size_t begin, std::size_t end,
                  const Box &region, std::size_t bucket_points, int depth) {
    if (begin == end)
      return -1;
    if (end - begin <= bucket_points)
      return makeLeaf(begin, end, region, depth);
    Eigen::Vector3d low = points_[order[begin]], high = low;
    for (std::size_t i = begin; i < end; ++i) {
      low = low.cwiseMin(points_[order[i]]);
      high = high.cwiseMax(points_[order[i]]);
    }
    int axis = 0;
    (high - low).maxCoeff(&axis);
    const std::size_t middle = begin + (end - begin) / 2;
    // Ties broken by index: the split does not depend on the input order.
    std::nth_element(order.begin() + begin, order.begin() + middle, order.begin() + end,
                     [&](VertexIndex a, VertexIndex b) {
                       const double pa = points_[a][axis], pb = points_[b][axis];
                       return pa < pb || (pa == pb && a < b);
                     });
    const double split = points_[order[middle]][axis];
    Box left_region = region, right_region = region;
    left_region.high[axis] = split;
    right_region.low[axis] = split;
    const int left = buildMedian(order, begin, middle, left_region, bucket_points, depth + 1);
    const int right = buildMedian(order, middle, end, right_region, bucket_points, depth + 1);
    return makeInner(region, axis, split, depth, left, right);
  }

  /// Splits the grid's cell range in halves, so the grid becomes a tree too.
  int buildGrid(std::vector<VertexIndex> &order, std::size_t begin, std::size_t end,
                const Box &region, std::array<int, 3> first, std::array<int, 3> last, int depth) {
    if (begin == end)
      return -1;
    const detail::GridHalves halves = detail::halveGrid(region, first, last, grid_low_, grid_cell_);
    if (halves.leaf)
      return makeLeaf(begin, end, region, depth);
    // Sides by the plane itself, so every point lies in its leaf's region:
    // a cell number computed as floor((p - low) / cell) can round across
    // the plane when coordinates span many orders of magnitude.
    const auto middle =
        std::stable_partition(order.begin() + begin, order.begin() + end, [&](VertexIndex v) {
          return points_[v][halves.axis] < halves.split;
        });
    const std::size_t middle_index = static_cast<std::size_t>(middle - order.begin());
    const int left = buildGrid(order, begin, middle_index, halves.left_region, first,
                               halves.left_last, depth + 1);
    const int right = buildGrid(order, middle_index, end, halves.right_region, halves.right_first,
                                last, depth + 1);
    return makeInner(region, halves.axis, halves.split, depth, left, right);
  }

  void numberLeaves(int root) {
    leaves_ = detail::numberLeaves(nodes_, root);
    for (int leaf : leaves_)
      for (VertexIndex v : nodes_[static_cast<std::size_t>(leaf)].points)
        leaf_of_[v] = nodes_[static_cast<std::size_t>(leaf)].first_leaf;
  }

  /// A leaf and its part of the order, until fillLeaves.
  struct LeafRange {
    int node;
    std::size_t begin, end;
  };

  const std::vector<Eigen::Vector3d> &points_;
  std::vector<Node> nodes_;
  std::vector<LeafRange> leaf_ranges_;
  std::vector<int> leaves_;
  std::vector<std::uint32_t> leaf_of_;
  int root_ = -1;
  Eigen::Vector3d grid_low_ = Eigen::Vector3d::Zero(), grid_cell_ = Eigen::Vector3d::Ones();
};

/// The median spacing of `members` (detail::medianSpacing); 0 for fewer
/// than 2 members.
double medianSpacing(const std::vector<Eigen::Vector3d> &points,
                     const std::vector<VertexIndex> &members) {
  return detail::medianSpacing(members.size(), detail::spacing_samples_per_bucket,
                               [&](std::size_t i) { return points[members[i]]; });
}

/// For each bucket, its median spacing (a bucket is big enough for this):
/// buckets differ, as a cloud's density varies. A bucket of fewer than 2
/// points takes the largest; when no bucket has 2 (a small cloud in a fine
/// grid), all take the whole cloud's, so that their margins reach their
/// neighbours and the seams can join them.
std::vector<double> bucketSpacings(const std::vector<Eigen::Vector3d> &points, BucketTree &tree) {
  const std::vector<int> &leaves = tree.leaves();
  std::vector<double> spacings(leaves.size());
  detail::parallelFor(std::size_t(0), leaves.size(), [&](std::size_t i) {
    spacings[i] = medianSpacing(points, tree.nodes()[static_cast<std::size_t>(leaves[i])].points);
  });
  double fallback = *std::max_element(spacings.begin(), spacings.end());
  if (!(fallback > 0)) {
    std::vector<VertexIndex> all(points.size());
    std::iota(all.begin(), all.end(), 0);
    fallback = medianSpacing(points, all);
  }
  for (double &spacing : spacings)
    if (!(spacing > 0))
      spacing = fallback;
  return spacings;
}

using detail::ProgressReporter;

class BucketedMesher {
public:
  BucketedMesher(const std::vector<Eigen::Vector3d> &points,
                 const std::vector<Eigen::Vector3f> *normals, const Parameters &parameters,
                 const Deadline *deadline, BucketExchange &exchange)
      : points_(points), normals_(normals), parameters_(parameters), deadline_(deadline),
        exchange_(exchange),
        tree_(points,
              parameters.bucket_points > 0 ? parameters.bucket_points : default_bucket_points,
              parameters.grid_buckets) {}

  BucketedSurface run() {
    std::vector<Node> &nodes = tree_.nodes();
    const std::vector<int> &leaves = tree_.leaves();
    std::vector<int> inner;
    int max_depth = 0;
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (nodes[i].axis >= 0) {
        inner.push_back(static_cast<int>(i));
        max_depth = std::max(max_depth, nodes[i].depth);
      }
    // This process's units: its leaves, and the zones whose first leaf it owns.
    std::vector<std::size_t> own_leaves;
    for (std::size_t i = 0; i < leaves.size(); ++i)
      if (owner(static_cast<std::uint32_t>(i)) == exchange_.process())
        own_leaves.push_back(i);
    std::size_t own_zones = 0;
    for (int index : inner)
      own_zones += owner(nodes[index].first_leaf) == exchange_.process();
    ProgressReporter progress(parameters_, own_leaves.size() + own_zones);
    surface_.statistics.buckets = leaves.size();
    surface_.statistics.seam_zones = inner.size();

    // Each bucket's margin follows its own spacing: a triangle is up to rho
    // local scales long, and a sparse bucket's scale is larger.
    const std::vector<double> spacings = detail::withThreads(
        parameters_.num_threads, [&] { return bucketSpacings(points_, tree_); });
    leaf_margin_.resize(spacings.size());
    for (std::size_t leaf = 0; leaf < spacings.size(); ++leaf)
      leaf_margin_[leaf] = detail::bucketMargin(parameters_.rho, spacings[leaf]);

    Clock::time_point stage = Clock::now();
    surface_.local_scale.assign(points_.size(), 0.0f);
    std::vector<BucketOutcome> leaf_outcomes(leaves.size());
    std::vector<std::size_t> margin_points(leaves.size(), 0);
    zone_figures_.assign(nodes.size(), ZoneFigures());
    // One process meshes every unit once what it reads is final; shared
    // among processes, the seams go level by level.
    const bool as_ready = exchange_.farm() == nullptr && exchange_.processes() == 1;
    if (as_ready) {
      meshAsReady(leaf_outcomes, margin_points, progress);
    } else if (UnitFarm *farm = exchange_.farm()) {
      // Only the units in flight keep their members.
      std::vector<std::vector<VertexIndex>> members(own_leaves.size());
      farm->mesh(
          own_leaves.size(),
          [&](std::size_t k) { return leafTask(nodes[leaves[own_leaves[k]]], members[k]); },
          [&](std::size_t k, BucketOutcome &&outcome) {
            const std::size_t i = own_leaves[k];
            leaf_outcomes[i] = std::move(outcome);
            margin_points[i] = keepLeaf(nodes[leaves[i]], leaf_outcomes[i], members[k]);
            std::vector<VertexIndex>().swap(members[k]);
            progress.unitDone();
          });
    } else {
      detail::withThreads(parameters_.num_threads, [&] {
        detail::parallelFor(tbb::blocked_range<std::size_t>(0, own_leaves.size(), 1),
                            [&](const tbb::blocked_range<std::size_t> &range) {
                              for (std::size_t k = range.begin(); k != range.end(); ++k) {
                                const std::size_t i = own_leaves[k];
                                margin_points[i] = meshLeaf(nodes[leaves[i]], leaf_outcomes[i]);
                                progress.unitDone();
                              }
                            });
      });
    }
    // Per leaf: d_med, failed, margin points; only the owner's are non-zero.
    std::vector<double> leaf_figures(3 * leaves.size(), 0.0);
    std::string first_error;
    for (std::size_t i : own_leaves) {
      const BucketOutcome &outcome = leaf_outcomes[i];
      addLeafTimings(outcome);
      leaf_figures[3 * i] = outcome.error.empty() ? outcome.d_med : 0.0;
      leaf_figures[3 * i + 1] = outcome.error.empty() ? 0.0 : 1.0;
      leaf_figures[3 * i + 2] = static_cast<double>(margin_points[i]);
      if (first_error.empty())
        first_error = outcome.error;
    }
    exchange_.sumOver(leaf_figures);
    // Seams read the scales of points that other processes' buckets own.
    exchange_.maxOver(surface_.local_scale);
    std::vector<double> bucket_d_meds;
    for (std::size_t i = 0; i < leaves.size(); ++i) {
      surface_.statistics.margin_points += static_cast<std::size_t>(leaf_figures[3 * i + 2]);
      if (leaf_figures[3 * i + 1] == 0.0)
        bucket_d_meds.push_back(leaf_figures[3 * i]);
      else
        ++surface_.statistics.failed_units;
    }
    if (bucket_d_meds.empty())
      detail::throwNoBucketMeshed(first_error);
    surface_.d_med = detail::medianBucketDMed(std::move(bucket_d_meds));
    // Meshed as ready, the seams' own time is what follows the last bucket.
    surface_.statistics.buckets_seconds =
        as_ready ? std::chrono::duration<double>(last_leaf_meshed_ - stage).count()
                 : secondsSince(stage);
    exchange_.stageDone("buckets");
    stage = as_ready ? last_leaf_meshed_ : Clock::now();
    if (!as_ready)
      stitchByLevels(inner, max_depth, progress);
    std::vector<double> seam_figures(3, 0.0); // points, triangles, failed units
    for (int index : inner) {
      const ZoneFigures &zone = zone_figures_[static_cast<std::size_t>(index)];
      surface_.delaunay_seconds += zone.delaunay_seconds;
      surface_.scaffold_seconds += zone.scaffold_seconds;
      surface_.greedy_seconds += zone.greedy_seconds;
      seam_figures[0] += static_cast<double>(zone.core_points);
      seam_figures[1] += static_cast<double>(zone.triangles);
      seam_figures[2] += zone.failed ? 1 : 0;
    }
    std::vector<double> timings = {surface_.delaunay_seconds, surface_.scaffold_seconds,
                                   surface_.greedy_seconds};
    exchange_.sumOver(seam_figures);
    exchange_.sumOver(timings);
    surface_.statistics.seam_points = static_cast<std::size_t>(seam_figures[0]);
    surface_.statistics.seam_triangles = static_cast<std::size_t>(seam_figures[1]);
    surface_.statistics.failed_units += static_cast<std::size_t>(seam_figures[2]);
    surface_.delaunay_seconds = timings[0];
    surface_.scaffold_seconds = timings[1];
    surface_.greedy_seconds = timings[2];
    exchange_.maxOver(may_pinch_);
    surface_.triangles = std::move(nodes[tree_.root()].triangles);
    // Points of buckets that could not be meshed take the typical scale.
    for (float &scale : surface_.local_scale)
      if (!(scale > 0))
        scale = static_cast<float>(surface_.d_med);
    // Kept triangles may pinch where their neighbours were cut away, and a
    // seam may fail to join two fixed fans at a vertex: bow-ties are possible
    // only at those vertices.
    if (exchange_.process() == 0) {
      std::vector<bool> may_pinch(points_.size(), false);
      for (std::size_t v = 0; v < points_.size(); ++v)
        may_pinch[v] = may_pinch_[v] != 0;
      detail::withThreads(parameters_.num_threads, [&] {
        surface_.statistics.bow_tie_triangles_removed =
            splitBowTies(surface_.triangles, points_.size(), may_pinch);
      });
    }
    surface_.statistics.seams_seconds = secondsSince(stage);
    return std::move(surface_);
  }

private:
  /// What the statistics keep of a stitched zone.
  struct ZoneFigures {
    std::size_t core_points = 0, triangles = 0;
    bool failed = false;
    double delaunay_seconds = 0, scaffold_seconds = 0, greedy_seconds = 0;
  };

  /// Several processes: the seams bottom-up, a level at a time. A zone's
  /// subtrees are complete when it is stitched, and zones of one depth are
  /// disjoint, so they run in parallel.
  void stitchByLevels(const std::vector<int> &inner, int max_depth, ProgressReporter &progress) {
    std::vector<Node> &nodes = nodes_();
    for (int depth = max_depth; depth >= 0; --depth) {
      std::vector<int> level;
      std::vector<BucketExchange::Transfer> transfers;
      for (int index : inner) {
        if (nodes[index].depth != depth)
          continue;
        const int zone_owner = owner(nodes[index].first_leaf);
        for (int child : nodes[index].children)
          if (const int child_owner = owner(nodes[child].first_leaf); child_owner != zone_owner)
            transfers.push_back({child_owner, zone_owner, &nodes[child].triangles});
        if (zone_owner == exchange_.process())
          level.push_back(index);
      }
      exchange_.moveTriangles(transfers);
      if (UnitFarm *farm = exchange_.farm()) {
        // Zones of one level are planned before any is stitched: planning
        // reads only the zone's own subtree and the scales, fixed by now.
        std::vector<Zone> zones(level.size());
        std::vector<std::size_t> meshed;
        for (std::size_t i = 0; i < level.size(); ++i) {
          zones[i] = planZone(nodes[level[i]], zonePoints(nodes[level[i]]));
          if (zones[i].core_points >= 3)
            meshed.push_back(i);
        }
        std::vector<BucketOutcome> outcomes(level.size());
        farm->mesh(
            meshed.size(), [&](std::size_t k) { return std::move(zones[meshed[k]].task); },
            [&](std::size_t k, BucketOutcome &&outcome) {
              outcomes[meshed[k]] = std::move(outcome);
            });
        for (std::size_t i = 0; i < level.size(); ++i) {
          keepZone(level[i], zones[i], outcomes[i]);
          progress.unitDone();
        }
      } else {
        detail::withThreads(parameters_.num_threads, [&] {
          detail::parallelFor(tbb::blocked_range<std::size_t>(0, level.size(), 1),
                              [&](const tbb::blocked_range<std::size_t> &range) {
                                for (std::size_t i = range.begin(); i != range.end(); ++i) {
                                  Node &node = nodes[level[i]];
                                  stitch(level[i], planZone(node, zonePoints(node)));
                                  progress.unitDone();
                                }
                              });
        });
      }
      exchange_.stageDone("seam level " + std::to_string(depth));
    }
  }

  /// One process: each bucket and zone as soon as what it reads is final
  /// (docs/algorithm.md section 5, "Order of the units"). The buckets go in
  /// their depth-first order; a zone is fed to the thread that finished the
  /// last unit it waited for, so the seams fill the buckets' tail.
  void meshAsReady(std::vector<BucketOutcome> &leaf_outcomes,
                   std::vector<std::size_t> &margin_points, ProgressReporter &progress) {
    std::vector<Node> &nodes = nodes_();
    unfinished_children_.assign(nodes.size(), 0);
    parent_.assign(nodes.size(), -1);
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (nodes[i].axis >= 0)
        for (int child : nodes[i].children) {
          parent_[static_cast<std::size_t>(child)] = static_cast<int>(i);
          ++unfinished_children_[i];
        }
    leaf_meshed_.assign(tree_.leaves().size(), 0);
    waiting_for_leaf_.assign(tree_.leaves().size(), {});
    missing_leaves_.assign(nodes.size(), 0);
    detail::withThreads(parameters_.num_threads, [&] {
      detail::parallelForEachFed(tree_.leaves(), [&](int index, const auto &feed) {
        Node &node = nodes[static_cast<std::size_t>(index)];
        if (node.axis < 0) {
          margin_points[node.first_leaf] = meshLeaf(node, leaf_outcomes[node.first_leaf]);
        } else {
          std::vector<VertexIndex> zone;
          if (!scalesFinal(index, zone))
            return; // fed again when the buckets it waits for are meshed
          stitch(index, planZone(node, zone));
        }
        progress.unitDone();
        for (int next : unitDone(index))
          feed(next);
      });
    });
  }

  /// Whether every bucket owning a point of zone `index`'s slab has been
  /// meshed, so the scales it reads are final; if so, `zone` gets its
  /// points. If not, the zone waits for those buckets.
  bool scalesFinal(int index, std::vector<VertexIndex> &zone) {
    const Node &node = nodes_()[static_cast<std::size_t>(index)];
    const std::vector<VertexIndex> near_plane = nearPlane(node);
    if (!waitForLeaves(index, near_plane))
      return false;
    zone = zonePoints(node, near_plane);
    return waitForLeaves(index, zone);
  }

  /// True when the buckets owning `points` are all meshed; otherwise zone
  /// `index` is registered to be fed again once they are.
  bool waitForLeaves(int index, const std::vector<VertexIndex> &points) {
    std::vector<bool> needed(tree_.leaves().size(), false);
    for (VertexIndex v : points)
      needed[tree_.leafOf(v)] = true;
    std::lock_guard<std::mutex> lock(ready_mutex_);
    int missing = 0;
    for (std::size_t leaf = 0; leaf < needed.size(); ++leaf)
      if (needed[leaf] && !leaf_meshed_[leaf]) {
        waiting_for_leaf_[leaf].push_back(index);
        ++missing;
      }
    missing_leaves_[static_cast<std::size_t>(index)] = missing;
    return missing == 0;
  }

  /// Marks unit `index` done; returns the zones it made ready.
  std::vector<int> unitDone(int index) {
    std::vector<int> ready;
    std::lock_guard<std::mutex> lock(ready_mutex_);
    const Node &node = nodes_()[static_cast<std::size_t>(index)];
    if (node.axis < 0) {
      leaf_meshed_[node.first_leaf] = 1;
      last_leaf_meshed_ = Clock::now(); // under the lock: the latest wins
      for (int zone : waiting_for_leaf_[node.first_leaf])
        if (--missing_leaves_[static_cast<std::size_t>(zone)] == 0)
          ready.push_back(zone);
      waiting_for_leaf_[node.first_leaf].clear();
    }
    // Last, so that its thread takes it first: the parent is on the way to
    // the root, the longest chain.
    const int parent = parent_[static_cast<std::size_t>(index)];
    if (parent >= 0 && --unfinished_children_[static_cast<std::size_t>(parent)] == 0)
      ready.push_back(parent);
    return ready;
  }
  BucketTask makeTask(const std::vector<VertexIndex> &members) const {
    BucketTask task;
    task.points.reserve(members.size());
    for (VertexIndex v : members)
      task.points.push_back(points_[v]);
    if (normals_) {
      task.normals.reserve(members.size());
      for (VertexIndex v : members)
        task.normals.push_back((*normals_)[v]);
    }
    return task;
  }

  static std::vector<Triangle> toGlobal(const std::vector<Triangle> &local,
                                        const std::vector<VertexIndex> &members) {
    std::vector<Triangle> global(local.size());
    for (std::size_t t = 0; t < local.size(); ++t)
      for (int k = 0; k < 3; ++k)
        global[t][k] = members[local[t][k]];
    return global;
  }

  /// A bucket: its points plus those within the margin around its region.
  /// `members` gets the task's points, ascending.
  BucketTask leafTask(const Node &leaf, std::vector<VertexIndex> &members) const {
    const std::uint32_t leaf_id = leaf.first_leaf;
    members = tree_.gather(leaf.region.expanded(leaf_margin_[leaf_id]));
    BucketTask task = makeTask(members);
    task.core.resize(members.size());
    for (std::size_t i = 0; i < members.size(); ++i)
      task.core[i] = tree_.leafOf(members[i]) == leaf_id;
    return task;
  }

  /// Keeps a bucket's outcome; returns how many margin points it meshed.
  std::size_t keepLeaf(Node &leaf, BucketOutcome &outcome,
                       const std::vector<VertexIndex> &members) {
    const std::uint32_t leaf_id = leaf.first_leaf;
    leaf.triangles = toGlobal(outcome.triangles, members);
    // Kept to the end, the buckets' own triangles would be a second surface.
    std::vector<Triangle>().swap(outcome.triangles);
    markMayPinch(outcome.cut_vertices, members);
    // Each point's scale is the one its own bucket measured, where its
    // neighbourhood is complete; seams reuse it. Buckets own disjoint points.
    if (!outcome.local_scale.empty())
      for (std::size_t i = 0; i < members.size(); ++i)
        if (tree_.leafOf(members[i]) == leaf_id)
          surface_.local_scale[members[i]] = outcome.local_scale[i];
    outcome.local_scale = {};
    return members.size() - leaf.points.size();
  }

  std::size_t meshLeaf(Node &leaf, BucketOutcome &outcome) {
    std::vector<VertexIndex> members;
    const BucketTask task = leafTask(leaf, members);
    outcome = meshBucket(task, parameters_, deadline_);
    return keepLeaf(leaf, outcome, members);
  }

  /// A seam zone planned: its points and, with 3 core points or more, the
  /// task to mesh.
  struct Zone {
    std::vector<VertexIndex> members;
    std::vector<bool> core;
    std::size_t core_points = 0;
    BucketTask task;
  };

  /// The widest margin of the subtree's buckets.
  double zoneMargin(const Node &node) const {
    return *std::max_element(leaf_margin_.begin() + node.first_leaf,
                             leaf_margin_.begin() + node.end_leaf);
  }

  Box zoneSlab(const Node &node, double half_width) const {
    return detail::zoneSlab(node.region, node.axis, node.split, zoneMargin(node), half_width);
  }

  /// The points within the margin of node's split plane.
  std::vector<VertexIndex> nearPlane(const Node &node) const {
    return tree_.gather(zoneSlab(node, zoneMargin(node)));
  }

  /// The zone along node's split plane: the points within rho times the
  /// largest scale among the points of `near_plane` (nearPlane) around them
  /// (ZoneReach). A triangle across the plane is shorter than that; a sparse
  /// part's reach can exceed the buckets' margin. Those of the subtree are
  /// its core; the others, of neighbouring subtrees, lie within the margin
  /// around the node's region.
  std::vector<VertexIndex> zonePoints(const Node &node,
                                      const std::vector<VertexIndex> &near_plane) const {
    float largest_scale = 0;
    Box bounds = detail::emptyBox();
    for (VertexIndex v : near_plane) {
      largest_scale = std::max(largest_scale, surface_.local_scale[v]);
      bounds.extend(points_[v]);
    }
    const Box slab = zoneSlab(node, parameters_.rho * largest_scale);
    detail::ZoneReach reach(bounds, node.axis, node.split, parameters_.rho, largest_scale);
    for (VertexIndex v : near_plane)
      reach.addScale(points_[v], surface_.local_scale[v]);
    std::vector<VertexIndex> zone = tree_.gather(slab);
    zone.erase(std::remove_if(zone.begin(), zone.end(),
                              [&](VertexIndex v) { return !reach.reaches(points_[v]); }),
               zone.end());
    return zone;
  }

  std::vector<VertexIndex> zonePoints(const Node &node) const {
    return zonePoints(node, nearPlane(node));
  }

  /// Plans the zone of `node` on its points `zone` (zonePoints): reads the
  /// subtree's triangles and the points' scales. Triangles of the subtree
  /// that touch the zone are fixed; their corners outside it are frozen.
  Zone planZone(const Node &node, const std::vector<VertexIndex> &zone) {
    // Every triangle of the subtree is tested: a lookup table, not a search.
    std::vector<bool> in_zone(points_.size(), false);
    for (VertexIndex v : zone)
      in_zone[v] = true;
    auto inZone = [&](VertexIndex v) { return in_zone[v]; };

    Zone planned;
    std::vector<Triangle> fixed;
    std::vector<VertexIndex> frozen;
    for (VertexIndex v : zone)
      planned.core_points += tree_.inSubtree(v, node);
    if (planned.core_points < 3)
      return planned;
    for (int child : node.children) {
      for (const Triangle &triangle : nodes_()[child].triangles) {
        bool touches = false;
        for (VertexIndex v : triangle)
          touches = touches || inZone(v);
        if (!touches)
          continue;
        fixed.push_back(triangle);
        for (VertexIndex v : triangle)
          if (!inZone(v))
            frozen.push_back(v);
      }
    }
    detail::sortUnique(frozen);
    std::vector<VertexIndex> &members = planned.members;
    members.reserve(zone.size() + frozen.size());
    std::merge(zone.begin(), zone.end(), frozen.begin(), frozen.end(), std::back_inserter(members));

    BucketTask &task = planned.task;
    task = makeTask(members);
    // No d_med given: a point without a scale (its bucket failed) takes the
    // zone's own measure, known without waiting for every bucket.
    task.local_scale.reserve(members.size());
    for (VertexIndex v : members)
      task.local_scale.push_back(surface_.local_scale[v]);
    task.core.resize(members.size());
    task.frozen.resize(members.size());
    for (std::size_t i = 0; i < members.size(); ++i) {
      const bool is_frozen = std::binary_search(frozen.begin(), frozen.end(), members[i]);
      task.frozen[i] = is_frozen;
      task.core[i] = !is_frozen && tree_.inSubtree(members[i], node);
    }
    planned.core = task.core;
    auto localIndex = [&](VertexIndex v) {
      return static_cast<VertexIndex>(std::lower_bound(members.begin(), members.end(), v) -
                                      members.begin());
    };
    task.fixed_triangles.reserve(fixed.size());
    for (const Triangle &triangle : fixed)
      task.fixed_triangles.push_back(
          {localIndex(triangle[0]), localIndex(triangle[1]), localIndex(triangle[2])});
    return planned;
  }

  /// The subtree's triangles, then the seam's, in a fixed order; and the
  /// zone's figures.
  void keepZone(int index, const Zone &zone, const BucketOutcome &outcome) {
    Node &node = nodes_()[static_cast<std::size_t>(index)];
    std::vector<Triangle> added;
    ZoneFigures &figures = zone_figures_[static_cast<std::size_t>(index)];
    figures.core_points = zone.core_points;
    if (zone.core_points >= 3) {
      added = toGlobal(outcome.triangles, zone.members);
      markMayPinch(outcome.cut_vertices, zone.members);
      for (std::size_t i = 0; i < zone.members.size(); ++i)
        if (zone.core[i])
          may_pinch_[zone.members[i]] = 1;
      figures.triangles = added.size();
      figures.failed = !outcome.error.empty();
      figures.delaunay_seconds = outcome.delaunay_seconds;
      figures.scaffold_seconds = outcome.scaffold_seconds;
      figures.greedy_seconds = outcome.greedy_seconds;
    }
    std::vector<Triangle> &merged = node.triangles;
    // Sized once: at the root this is the whole surface, and growing it by
    // doubling would hold up to three times its size while copying.
    merged.reserve(nodes_()[node.children[0]].triangles.size() +
                   nodes_()[node.children[1]].triangles.size() + added.size());
    for (int child : node.children) {
      std::vector<Triangle> &part = nodes_()[child].triangles;
      merged.insert(merged.end(), part.begin(), part.end());
      std::vector<Triangle>().swap(part);
    }
    merged.insert(merged.end(), added.begin(), added.end());
  }

  /// Meshes a planned zone (with fewer than 3 core points, nothing) and
  /// keeps its triangles with the subtree's.
  void stitch(int index, const Zone &zone) {
    BucketOutcome outcome;
    if (zone.core_points >= 3)
      outcome = meshBucket(zone.task, parameters_, deadline_);
    keepZone(index, zone, outcome);
  }

  std::vector<Node> &nodes_() { return tree_.nodes(); }

  int owner(std::uint32_t leaf) const {
    return bucketOwner(leaf, tree_.leaves().size(), exchange_.processes());
  }

  /// Units write disjoint points (their core), so bytes, not bits.
  void markMayPinch(const std::vector<VertexIndex> &local,
                    const std::vector<VertexIndex> &members) {
    for (VertexIndex v : local)
      may_pinch_[members[v]] = 1;
  }

  void addLeafTimings(const BucketOutcome &outcome) {
    surface_.delaunay_seconds += outcome.delaunay_seconds;
    surface_.scaffold_seconds += outcome.scaffold_seconds;
    surface_.greedy_seconds += outcome.greedy_seconds;
  }

  const std::vector<Eigen::Vector3d> &points_;
  const std::vector<Eigen::Vector3f> *normals_;
  const Parameters &parameters_;
  const Deadline *deadline_;
  BucketExchange &exchange_;
  BucketTree tree_;
  std::vector<double> leaf_margin_; // by leaf number
  BucketedSurface surface_;
  std::vector<std::uint8_t> may_pinch_ = std::vector<std::uint8_t>(points_.size(), 0);
  std::vector<ZoneFigures> zone_figures_; // by node
  // meshAsReady's schedule, under ready_mutex_: by node, then by leaf.
  std::mutex ready_mutex_;
  std::vector<int> parent_, unfinished_children_, missing_leaves_;
  std::vector<std::uint8_t> leaf_meshed_;
  std::vector<std::vector<int>> waiting_for_leaf_;
  Clock::time_point last_leaf_meshed_;
};

} // namespace

BucketOutcome meshBucket(const BucketTask &task, const Parameters &parameters,
                         const Deadline *deadline) {
  BucketOutcome outcome;
  if (task.points.size() < 3) {
    outcome.error = detail::too_few_unit_points;
    return outcome;
  }
  try {
    ScaffoldOptions options;
    options.rho = parameters.rho;
    options.num_threads = 1;
    options.normals = parameters.use_normals && !task.normals.empty() ? &task.normals : nullptr;
    options.normal_weight = parameters.normal_weight;
    options.d_med = task.d_med;
    options.local_scale = task.local_scale.empty() ? nullptr : &task.local_scale;
    options.fixed_triangles = task.fixed_triangles.empty() ? nullptr : &task.fixed_triangles;
    options.frozen_vertices = task.frozen.empty() ? nullptr : &task.frozen;
    if (deadline)
      deadline->check("the buckets");
    MeshedPoints meshed =
        meshPoints(task.points, options, parameters, deadline, false, [&](const MedialScaffold &) {
          if (deadline)
            deadline->check("the buckets");
        });
    outcome.d_med = meshed.d_med;
    outcome.local_scale = std::move(meshed.local_scale);
    outcome.delaunay_seconds = meshed.delaunay_seconds;
    outcome.scaffold_seconds = meshed.scaffold_seconds;
    outcome.greedy_seconds = meshed.greedy_seconds;
    for (const Triangle &triangle : meshed.triangles) {
      if (task.core[triangle[0]] && task.core[triangle[1]] && task.core[triangle[2]]) {
        outcome.triangles.push_back(triangle);
        continue;
      }
      for (VertexIndex v : triangle)
        if (task.core[v])
          outcome.cut_vertices.push_back(v);
    }
    detail::sortUnique(outcome.cut_vertices);
  } catch (const TimeLimitExceeded &) {
    throw; // the whole run stops, not just this unit
  } catch (const ReconstructionError &error) {
    outcome.error = error.what();
    outcome.triangles.clear();
    outcome.local_scale.clear();
  }
  return outcome;
}

bool usesBuckets(std::size_t points, const Parameters &parameters) {
  if (parameters.grid_buckets > 0)
    return true;
  if (parameters.bucket_points > 0)
    return points > parameters.bucket_points;
  return points > automatic_bucketing_threshold;
}

BucketedSurface meshInBuckets(const std::vector<Eigen::Vector3d> &points,
                              const std::vector<Eigen::Vector3f> *normals,
                              const Parameters &parameters, const Deadline *deadline,
                              BucketExchange *exchange) {
  BucketExchange one_process;
  return BucketedMesher(points, normals, parameters, deadline, exchange ? *exchange : one_process)
      .run();
}

} // namespace pcl_ms
