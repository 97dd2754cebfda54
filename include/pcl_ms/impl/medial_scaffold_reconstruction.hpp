// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <pcl_ms/medial_scaffold_reconstruction.h>
#include <pcl_ms/reconstruct.h>

#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h> // pcl::traits::has_normal_v

#include <algorithm>
#include <cstddef>
#include <exception>
#include <limits>
#include <new>
#include <string>

namespace pcl {

template <typename PointInT>
MedialScaffoldReconstruction<PointInT>::MedialScaffoldReconstruction() {
  // The core builds its own Delaunay structure: no search tree needed.
  check_tree_ = false;
}

template <typename PointInT>
void MedialScaffoldReconstruction<PointInT>::reconstruct(pcl::PolygonMesh &output) {
  if (!input_) {
    error_message_ = "no input cloud was given (call setInputCloud first)";
    PCL_ERROR("[pcl::%s::reconstruct] %s\n", getClassName().c_str(), error_message_.c_str());
    output = pcl::PolygonMesh();
    return;
  }
  SurfaceReconstruction<PointInT>::reconstruct(output);
}

template <typename PointInT>
void MedialScaffoldReconstruction<PointInT>::reconstruct(pcl::PointCloud<PointInT> &points,
                                                         std::vector<pcl::Vertices> &polygons) {
  if (!input_) {
    error_message_ = "no input cloud was given (call setInputCloud first)";
    PCL_ERROR("[pcl::%s::reconstruct] %s\n", getClassName().c_str(), error_message_.c_str());
    points.clear();
    polygons.clear();
    return;
  }
  SurfaceReconstruction<PointInT>::reconstruct(points, polygons);
}

template <typename PointInT>
bool MedialScaffoldReconstruction<PointInT>::runCore(std::vector<pcl::Vertices> &polygons) {
  polygons.clear();
  result_ = pcl_ms::Result();
  error_message_.clear();

  pcl_ms::PointView view;
  view.xyz = input_->empty() ? nullptr : &(*input_)[0].x;
  view.size = input_->size();
  view.stride = sizeof(PointInT);
  // PCLBase fills indices_ with 0..n-1 when the user gave none; pass only a
  // real subset so the core can skip the indirection.
  if (indices_ && indices_->size() != input_->size())
    view.indices = pcl_ms::IndexList(*indices_);
  else if (indices_) {
    for (std::size_t i = 0; i < indices_->size(); ++i)
      if (static_cast<std::size_t>((*indices_)[i]) != i) {
        view.indices = pcl_ms::IndexList(*indices_);
        break;
      }
  }

  if (parameters_.use_normals) {
    if (normals_) {
      if (normals_->size() != input_->size()) {
        error_message_ = "the normal cloud has " + std::to_string(normals_->size()) +
                         " points but the input has " + std::to_string(input_->size());
        PCL_ERROR("[pcl::%s::reconstruct] %s\n", getClassName().c_str(), error_message_.c_str());
        return false;
      }
      view.normals = normals_->empty() ? nullptr : &(*normals_)[0].normal_x;
      view.normal_stride = sizeof(pcl::Normal);
    } else if constexpr (pcl::traits::has_normal_v<PointInT>) {
      view.normals = input_->empty() ? nullptr : &(*input_)[0].normal_x;
      view.normal_stride = sizeof(PointInT);
    } else {
      error_message_ = "normals were requested but none were given and the point type has none";
      PCL_ERROR("[pcl::%s::reconstruct] %s\n", getClassName().c_str(), error_message_.c_str());
      return false;
    }
  }

  std::vector<pcl_ms::Triangle> initial;
  initial.reserve(initial_triangles_.size());
  const bool preferred =
      parameters_.initial_triangles_mode == pcl_ms::InitialTrianglesMode::preferred;
  for (std::size_t t = 0; t < initial_triangles_.size(); ++t) {
    const auto &vertices = initial_triangles_[t].vertices;
    const bool negative =
        std::any_of(vertices.begin(), vertices.end(), [](pcl::index_t v) { return v < 0; });
    if ((vertices.size() != 3 || negative) && preferred) {
      // No valid point: the core leaves it out and counts it.
      constexpr auto invalid = std::numeric_limits<pcl_ms::VertexIndex>::max();
      initial.push_back({invalid, invalid, invalid});
      continue;
    }
    if (vertices.size() != 3 || negative) {
      error_message_ = "initial polygon " + std::to_string(t) +
                       (negative ? " has a negative index"
                                 : " has " + std::to_string(vertices.size()) + " vertices, not 3");
      PCL_ERROR("[pcl::%s::reconstruct] %s\n", getClassName().c_str(), error_message_.c_str());
      return false;
    }
    initial.push_back({static_cast<pcl_ms::VertexIndex>(vertices[0]),
                       static_cast<pcl_ms::VertexIndex>(vertices[1]),
                       static_cast<pcl_ms::VertexIndex>(vertices[2])});
  }

  pcl_ms::Parameters parameters = parameters_;
  const Eigen::Vector4f &origin = input_->sensor_origin_;
  if (!parameters.viewpoint && use_sensor_origin_ &&
      (input_->isOrganized() || origin.head<3>() != Eigen::Vector3f::Zero()))
    parameters.viewpoint = {{origin[0], origin[1], origin[2]}};

  bool failed = true;
  try {
    result_ = pcl_ms::reconstruct(view, parameters, initial);
    failed = false;
  } catch (const pcl_ms::ReconstructionError &error) {
    error_message_ = error.what();
  } catch (const std::bad_alloc &) {
    error_message_ = "out of memory";
  } catch (const std::exception &error) {
    // Nothing may escape a PCL algorithm: a failure is reported like any other.
    error_message_ = std::string("unexpected failure: ") + error.what();
  }
  if (failed) {
    PCL_ERROR("[pcl::%s::reconstruct] %s\n", getClassName().c_str(), error_message_.c_str());
    return false;
  }

  polygons.resize(result_.triangles.size());
  for (std::size_t t = 0; t < result_.triangles.size(); ++t) {
    const pcl_ms::Triangle &triangle = result_.triangles[t];
    polygons[t].vertices.assign(triangle.begin(), triangle.end());
  }
  return true;
}

template <typename PointInT>
void MedialScaffoldReconstruction<PointInT>::performReconstruction(pcl::PolygonMesh &output) {
  // The base class already copied the whole input (all fields) into output.cloud.
  runCore(output.polygons);
}

template <typename PointInT>
void MedialScaffoldReconstruction<PointInT>::performReconstruction(
    pcl::PointCloud<PointInT> &points, std::vector<pcl::Vertices> &polygons) {
  points = *input_;
  runCore(polygons);
}

template <typename PointInT>
std::vector<pcl::Vertices> MedialScaffoldReconstruction<PointInT>::getBoundaryLoops() const {
  std::vector<pcl::Vertices> loops(result_.boundary_loops.size());
  for (std::size_t l = 0; l < loops.size(); ++l)
    loops[l].vertices.assign(result_.boundary_loops[l].begin(), result_.boundary_loops[l].end());
  return loops;
}

} // namespace pcl

#define PCL_INSTANTIATE_MedialScaffoldReconstruction(T)                                            \
  template class PCL_EXPORTS pcl::MedialScaffoldReconstruction<T>;
