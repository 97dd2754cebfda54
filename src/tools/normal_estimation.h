// SPDX-License-Identifier: GPL-3.0-or-later
//
// Normals for a cloud that has none, estimated with PCL from each point's
// nearest neighbours, so that the reconstruction can be guided by them.
#pragma once

#include <pcl/PCLPointCloud2.h>

#include <array>
#include <optional>
#include <string>

namespace pcl_ms_tools {

/// Appends FLOAT32 normal_x, normal_y, normal_z to `cloud`: the normal of
/// the plane fitted to each point's `neighbours` nearest points (PCL's
/// NormalEstimation), turned towards `viewpoint` when there is one. Points
/// without a position, or whose neighbours fit no plane, get NaN (which the
/// reconstruction treats as no normal). False with `error` set when
/// `neighbours` < 3 or the cloud already has normals.
bool estimateNormals(pcl::PCLPointCloud2 &cloud, int neighbours,
                     const std::optional<std::array<double, 3>> &viewpoint, std::string &error);

} // namespace pcl_ms_tools
