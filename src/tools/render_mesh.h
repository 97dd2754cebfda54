// SPDX-License-Identifier: GPL-3.0-or-later
//
// Off-screen pictures of triangle meshes for pcl_ms_compare and the README:
// shaded faces, boundary edges in blue and non-manifold edges in red, as the
// paper draws them. Works without a display: with no usable DISPLAY, the
// first render starts a private Xvfb (Debian package xvfb) that ends with
// the process. Renders may come from any thread; they run one at a time.
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

// A view that frames the points from a fixed oblique direction: from the
// front left and a little below, with y up (the Stanford scans' frame), so
// the bunny's base holes show. Pass the input cloud, not each method's mesh,
// so every picture of a comparison gets the same camera.
RenderView viewFramingPoints(const std::vector<Eigen::Vector3d> &points);

struct RenderOptions {
  int width = 800;
  int height = 800;
  std::string caption; // drawn at the top of the picture when not empty
};

// Writes a PNG (RGB, white background). Triangles with a missing or
// non-finite vertex are skipped. Returns false with a one-line reason in
// `error` when it cannot render or write.
bool renderMeshPng(const std::vector<Eigen::Vector3d> &vertices,
                   const std::vector<pcl_ms::Triangle> &triangles, const RenderView &view,
                   const RenderOptions &options, const std::string &png_path, std::string &error);

// Puts PNGs (same height and pixel format) next to each other, left to
// right, into one PNG. Returns false with a one-line reason in `error`.
bool composeSideBySide(const std::vector<std::string> &png_paths, const std::string &output_path,
                       std::string &error);

} // namespace pcl_ms_tools
