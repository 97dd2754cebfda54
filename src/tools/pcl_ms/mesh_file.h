// SPDX-License-Identifier: GPL-3.0-or-later
// Reading a triangle mesh (a reference surface, an initial soup) from a file,
// without PCL: the core's tests use it too. Reports failure by returning
// false with a one-line reason; never throws, never crashes on a bad file.
#pragma once

#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace pcl_ms {

/// Lower-case extension of `path` including the dot (".pcd"), or "" if none.
std::string fileExtension(const std::string &path);

/// Loads a triangle mesh (for instance a reference surface) from .ply, .obj,
/// .off, legacy .vtk (POLYDATA, ascii or binary) or .stl (ascii or binary).
/// Polygons with more than three corners are fan-triangulated. STL repeats
/// each corner in every facet: corners at the same float position become one
/// vertex (numbered in order of first use) and facets left with two equal
/// corners are dropped. Fails on meshes without faces, on faces that
/// reference missing vertices and on non-finite STL coordinates.
bool loadMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
              std::vector<Triangle> &triangles, std::string &error);

namespace io_detail {
/// The mesh reader for the file's extension; faces may be absent.
bool readMeshFile(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                  std::vector<Triangle> &triangles, std::string &reason);
} // namespace io_detail

} // namespace pcl_ms
