// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh readers of our own for .ply, .obj, .off, legacy .vtk and .stl, so that
// every format reports the same kind of errors. Internal to the library: not
// installed; loadMesh() in mesh_file.h is the entry for the tools.
#pragma once

#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace pcl_ms {
namespace io_detail {

bool loadPlyMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error);
bool loadObjMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error);
bool loadOffMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error);
bool loadVtkMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error);
/// ASCII or binary STL (stl_reader.cpp). Corners at bitwise-equal float
/// positions (-0 counted as +0) become one vertex, numbered in order of first
/// use; facets left with two equal corners are dropped. Non-finite
/// coordinates are an error.
bool loadStlMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error);

} // namespace io_detail
} // namespace pcl_ms
