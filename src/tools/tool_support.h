// SPDX-License-Identifier: GPL-3.0-or-later
//
// Small pieces the command-line programs share: exit codes, quieting PCL's
// console and reading a cloud's positions.
#pragma once

#include <pcl_ms/types.h>

#include <Eigen/Core>
#include <pcl/PCLPointCloud2.h>
#include <pcl/console/print.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace pcl_ms_tools {

enum ExitCode { kSuccess = 0, kBadArguments = 1, kIoFailure = 2, kReconstructionFailure = 3 };

/// Prints "error: <reason>" as one line on stderr and returns `code`.
int fail(int code, const std::string &reason);

/// A program's main: runs `run`; an exception that escapes it becomes one
/// error line and `failure_code`, never an abort.
int runGuarded(int (*run)(int, char **), int argc, char **argv, int failure_code);

/// PCL's readers and algorithms explain failures on the console themselves;
/// the tools report one line of their own instead.
class SilencePclMessages {
public:
  SilencePclMessages() : previous_(pcl::console::getVerbosityLevel()) {
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  }
  ~SilencePclMessages() { pcl::console::setVerbosityLevel(previous_); }
  SilencePclMessages(const SilencePclMessages &) = delete;
  SilencePclMessages &operator=(const SilencePclMessages &) = delete;

private:
  pcl::console::VERBOSITY_LEVEL previous_;
};

/// The cloud's points with finite x, y, z, in order; returns how many were
/// skipped. The cloud must have float x, y, z (pcl_ms::loadPointCloud ensures it).
std::size_t finitePoints(const pcl::PCLPointCloud2 &cloud, pcl::PointCloud<pcl::PointXYZ> &points);

std::vector<Eigen::Vector3d> positions(const pcl::PointCloud<pcl::PointXYZ> &points);

/// The viewpoint the PCL class would take from a loaded cloud: its sensor
/// origin (a PCD's VIEWPOINT) when the cloud is organized (a depth frame)
/// or the origin is not zero; none otherwise.
std::optional<std::array<double, 3>> sensorViewpoint(const pcl::PCLPointCloud2 &cloud,
                                                     const Eigen::Vector4f &sensor_origin);

/// The core's view of the cloud's points (no copy: valid while they are).
pcl_ms::PointView pointView(const pcl::PointCloud<pcl::PointXYZ> &points);

} // namespace pcl_ms_tools
