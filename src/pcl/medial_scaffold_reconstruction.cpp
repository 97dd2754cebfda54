// SPDX-License-Identifier: GPL-3.0-or-later
// Explicit instantiations for the common PCL point types, as PCL's own
// surface module does; other types work with PCL_NO_PRECOMPILE.
#include <pcl_ms/impl/medial_scaffold_reconstruction.hpp>

#include <pcl/impl/instantiate.hpp>
#include <pcl/point_types.h>

// clang-format off
PCL_INSTANTIATE(MedialScaffoldReconstruction,
                (pcl::PointXYZ)(pcl::PointXYZI)(pcl::PointXYZRGB)(pcl::PointXYZRGBA)
                (pcl::PointNormal)(pcl::PointXYZRGBNormal)(pcl::PointXYZINormal))
// clang-format on
