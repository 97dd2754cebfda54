// SPDX-License-Identifier: GPL-3.0-or-later
//
// Off-screen pictures of triangle meshes for pcl_ms_compare and the README:
// shaded faces, boundary edges in blue and non-manifold edges in red, as the
// paper draws them. Works without a display.
#pragma once

#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace pcl_ms_tools {

// One camera for every picture of a comparison, so they line up side by side.
struct RenderView {
  Eigen::Vector3d look_at = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d(0, 0, 1); // from the object towards the camera
  Eigen::Vector3d up = Eigen::Vector3d(0, 1, 0);
  double distance = 1; // camera distance from look_at
};

// A view that frames the bounding box of the points from a fixed oblique angle.
RenderView viewFramingPoints(const std::vector<Eigen::Vector3d> &points);

struct RenderOptions {
  int width = 800;
  int height = 800;
  std::string caption; // drawn at the top of the picture when not empty
};

// Writes a PNG. Returns false with a one-line reason in `error` when it cannot.
bool renderMeshPng(const std::vector<Eigen::Vector3d> &vertices,
                   const std::vector<pcl_ms::Triangle> &triangles, const RenderView &view,
                   const RenderOptions &options, const std::string &png_path, std::string &error);

// Puts PNGs (same height) next to each other into one PNG.
bool composeSideBySide(const std::vector<std::string> &png_paths, const std::string &output_path,
                       std::string &error);

} // namespace pcl_ms_tools
