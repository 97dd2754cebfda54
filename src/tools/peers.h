// SPDX-License-Identifier: GPL-3.0-or-later
//
// The methods pcl_ms_compare sets side by side, each run on the same points:
// pcl_ms itself, PCL's greedy projection triangulation (GP3) and Poisson
// reconstruction, and CGAL's advancing-front surface reconstruction (AFSR).
// How the peers are configured is described with PeerSettings and in the
// README ("Comparing with other methods").
#pragma once

#include <pcl_ms/types.h>

#include <Eigen/Core>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace pcl_ms_tools {

enum class Method { pcl_ms, gp3, poisson, afsr };

/// Every method, in the order the tools run and list them.
const std::vector<Method> &allMethods();
/// Short lower-case name used on the command line and for file names ("gp3").
std::string methodKey(Method method);
/// Name for tables and pictures ("PCL GP3").
std::string methodLabel(Method method);
/// Accepts a methodKey (case-insensitive) or "ours" for pcl_ms.
bool parseMethod(const std::string &text, Method &method);

struct PeerSettings {
  /// Where a one-view scan was taken from, for pcl_ms (Parameters::viewpoint):
  /// pcl_ms_compare sets it to a depth frame's sensor origin.
  std::optional<std::array<double, 3>> viewpoint;
  /// Neighbours for PCL's NormalEstimation (GP3, Poisson), as in PCL's
  /// tutorials, and for the minimum-spanning-tree orientation that follows.
  int normal_neighbours = 20;
  /// GP3's search radius is this multiple of the cloud's spacing, the mean
  /// distance of a point to its 6 nearest neighbours. GP3 only connects
  /// points closer than the radius, so it must exceed the local edge length
  /// mu * nearest-neighbour distance, with room for sparser parts. 4 gives
  /// 0.030 on PCL's bun0.pcd, where PCL's tutorial uses 0.025; on the bunny,
  /// factors from 2.5 to 8 change GP3's recall by less than 0.3 points.
  double gp3_radius_factor = 4.0;
  double gp3_mu = 2.5;                  // PCL's tutorial value
  int gp3_max_nearest_neighbours = 100; // PCL's tutorial value
  /// Octree depth of Poisson reconstruction: 8 is PCL's default; its grid of
  /// 256 cells a side is finer than the spacing of clouds up to about 10^5
  /// points on a closed object, so detail is limited by the data, not by it.
  int poisson_depth = 8;
  /// pcl_ms threads; 1 so that every method runs single-threaded.
  int threads = 1;
  /// pcl_ms with Parameters::allow_non_manifold (seams where sheets meet);
  /// the other methods ignore it.
  bool non_manifold = false;
};

struct StageTime {
  std::string name;
  double seconds = 0;
};

struct PeerRun {
  Method method = Method::pcl_ms;
  bool ok = false;
  std::string error; // one line when !ok
  /// Mesh vertices: the input points, in order, for the interpolating methods
  /// (pcl_ms, GP3, AFSR), so triangles index the input; new points for Poisson.
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  bool vertices_are_input = true;
  std::vector<StageTime> stages; // wall-clock seconds of each stage, in order
  /// Peak resident memory (VmHWM) of the process that ran the method, MiB.
  double peak_mb = 0;
  /// Resident memory of that process when the method started (runPeerInChild:
  /// about what the caller held at the fork), MiB; 0 where unknown.
  double start_mb = 0;
  /// How the method was configured for these points (radius picked, normals
  /// that could not be oriented), one line.
  std::string configuration;

  double seconds() const;
};

/// Called with a stage's name as it starts ("normals", "triangulation").
using StageCallback = std::function<void(const std::string &stage)>;

/// Runs one method in this process. `points` must all be finite; failures of
/// the method (an exception, an empty result) give ok == false, never a throw.
/// peak_mb is this process's peak so far.
PeerRun runPeer(Method method, const pcl::PointCloud<pcl::PointXYZ> &points,
                const PeerSettings &settings, const StageCallback &on_stage = {});

/// The same in a forked child (see child_process.h), so that peak_mb is the
/// method's own peak; a crash of the method is reported, not inherited.
PeerRun runPeerInChild(Method method, const pcl::PointCloud<pcl::PointXYZ> &points,
                       const PeerSettings &settings, const StageCallback &on_stage = {});

} // namespace pcl_ms_tools
