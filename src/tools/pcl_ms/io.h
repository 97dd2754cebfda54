// SPDX-License-Identifier: GPL-3.0-or-later
// File input and output for the tools, tests and benchmarks: point clouds in,
// reference meshes in, reconstructed meshes out. Every function reports
// failure by returning false with a one-line reason in `error`; none throws
// and none crashes on truncated or garbage files (headers are checked before
// PCL's readers are trusted with them).
#pragma once

#include <pcl_ms/mesh_file.h> // loadMesh, fileExtension
#include <pcl_ms/types.h>

#include <Eigen/Core>
#include <pcl/PCLPointCloud2.h>
#include <pcl/PolygonMesh.h>

#include <string>
#include <vector>

namespace pcl_ms {

/// Loads a point cloud chosen by extension (case-insensitive):
///  - .pcd: ascii, binary or binary_compressed (PCL's reader);
///  - .ply: a point cloud or the vertices of a mesh (PCL's reader); range
///    scans with a `range_grid` element yield their vertices only, unorganized;
///  - .xyz / .txt: whitespace-separated columns, 3 (x y z) or 6 (x y z nx ny
///    nz) per line; blank lines and `#` comments are skipped;
///  - .obj, .off, .vtk (legacy POLYDATA): the vertices of a mesh, in file
///    order, as x y z (faces, if any, are read and dropped);
///  - .stl (ascii or binary): the mesh's vertices, each position once (STL
///    repeats a corner in every facet), in order of first use.
/// On success `cloud` has FLOAT32 fields x, y, z (plus whatever else the file
/// holds) and at least one point: coordinates read as double (text, mesh
/// files, FLOAT64 PCD or PLY fields, narrowed in place with FLOAT64 normals)
/// are rounded, and the file is refused when that moves points by over 10 %
/// of their typical spacing (float_coordinates.h). On failure `cloud` is
/// left empty.
/// `sensor_origin`, when given, receives a PCD file's VIEWPOINT position
/// (zero for the other formats and on failure).
bool loadPointCloud(const std::string &path, pcl::PCLPointCloud2 &cloud, std::string &error,
                    Eigen::Vector4f *sensor_origin = nullptr);

/// True when `path` has an extension saveMesh() can write (.ply, .vtk, .obj).
bool isMeshOutputSupported(const std::string &path);

/// Saves `mesh` chosen by extension: .ply (binary unless `binary` is false),
/// .vtk (legacy ascii) or .obj (ascii). The cloud must have FLOAT32 x, y, z
/// and every polygon must index it. Which other fields survive depends on the
/// format: PLY keeps rgb/rgba, normals and curvature; OBJ keeps normals; VTK
/// keeps rgb. On failure no partial file is left behind.
bool saveMesh(const std::string &path, const pcl::PolygonMesh &mesh, std::string &error,
              bool binary = true);

/// Saves a medial axis as .ply: element vertex (float x, y, z, radius and
/// uchar inside: MedialAxis::Side) and element edge (int vertex1, vertex2),
/// binary unless `binary` is false. On failure no partial file is left.
bool saveMedialAxis(const std::string &path, const MedialAxis &axis, std::string &error,
                    bool binary = true);

/// True when the cloud has FLOAT32 fields normal_x, normal_y and normal_z.
bool hasNormals(const pcl::PCLPointCloud2 &cloud);

} // namespace pcl_ms
