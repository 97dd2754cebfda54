// SPDX-License-Identifier: GPL-3.0-or-later
//
// Mesh files without the points that have no position: an organized depth
// frame keeps its missing pixels as NaN rows, which mesh viewers choke on.
#pragma once

#include <pcl/PolygonMesh.h>

#include <cstddef>

namespace pcl_ms_tools {

/// Removes from `mesh.cloud` the points whose x, y or z is not finite and
/// that no polygon uses, and renumbers the polygons to match. The cloud
/// becomes unorganized (height 1). Returns how many points went; a cloud
/// without FLOAT32 x, y, z is left as it is.
std::size_t dropNonFiniteVertices(pcl::PolygonMesh &mesh);

} // namespace pcl_ms_tools
