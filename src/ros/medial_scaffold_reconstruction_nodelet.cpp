// SPDX-License-Identifier: GPL-3.0-or-later
// ROS 1 nodelet pcl_ms/MedialScaffoldReconstructionNodelet: PointCloud2 in,
// pcl_msgs/PolygonMesh and two RViz markers out. Everything but the message
// plumbing lives in cloud_meshing.h, which knows nothing of ROS.
#include "cloud_meshing.h"

#include <nodelet/nodelet.h>
#include <pcl_conversions/pcl_conversions.h>
#include <pcl_msgs/PolygonMesh.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/Marker.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

namespace pcl_ms {

class MedialScaffoldReconstructionNodelet : public nodelet::Nodelet {
private:
  using Clock = std::chrono::steady_clock;

  void onInit() override;
  void readParameters(ros::NodeHandle &private_node);
  void readViewpoint(ros::NodeHandle &private_node);
  void cloudCallback(const sensor_msgs::PointCloud2ConstPtr &message);
  /// True when meshed; `report` is the line to log either way.
  bool meshAndPublish(const sensor_msgs::PointCloud2 &message, Clock::time_point received,
                      std::string &report);
  void publishMarkers(const std_msgs::Header &header, const pcl::PCLPointCloud2 &cloud,
                      const ros_bridge::MeshingOutcome &outcome);

  pcl_ms::Parameters parameters_;
  int queue_size_ = 1;
  bool latch_ = false;
  bool skip_if_busy_ = false;

  ros::Subscriber cloud_subscriber_;
  ros::Publisher mesh_publisher_;
  ros::Publisher mesh_marker_publisher_;
  ros::Publisher boundary_marker_publisher_;

  std::atomic<bool> busy_{false};
  std::atomic<std::size_t> dropped_clouds_{0};
};

namespace {

double secondsBetween(std::chrono::steady_clock::time_point start,
                      std::chrono::steady_clock::time_point end) {
  return std::chrono::duration<double>(end - start).count();
}

visualization_msgs::MarkerPtr makeMarker(const std_msgs::Header &header, const char *name_space,
                                         std::int32_t type) {
  visualization_msgs::MarkerPtr marker(new visualization_msgs::Marker);
  marker->header = header;
  marker->ns = name_space;
  marker->type = type;
  marker->pose.orientation.w = 1.0;
  marker->color.a = 1.0f;
  return marker;
}

void fillMarker(const ros_bridge::MarkerGeometry &geometry, visualization_msgs::Marker &marker) {
  marker.points.resize(geometry.points.size());
  for (std::size_t i = 0; i < geometry.points.size(); ++i) {
    marker.points[i].x = geometry.points[i][0];
    marker.points[i].y = geometry.points[i][1];
    marker.points[i].z = geometry.points[i][2];
  }
  marker.colors.resize(geometry.colors.size());
  for (std::size_t i = 0; i < geometry.colors.size(); ++i) {
    marker.colors[i].r = geometry.colors[i][0];
    marker.colors[i].g = geometry.colors[i][1];
    marker.colors[i].b = geometry.colors[i][2];
    marker.colors[i].a = geometry.colors[i][3];
  }
  // RViz refuses an ADD marker without points; DELETE clears the old one.
  marker.action =
      marker.points.empty() ? visualization_msgs::Marker::DELETE : visualization_msgs::Marker::ADD;
}

} // namespace

void MedialScaffoldReconstructionNodelet::readParameters(ros::NodeHandle &private_node) {
  private_node.param("rho", parameters_.rho, parameters_.rho);
  private_node.param("fill_holes", parameters_.fill_holes_max_edges,
                     parameters_.fill_holes_max_edges);
  private_node.param("use_normals", parameters_.use_normals, parameters_.use_normals);
  private_node.param("threads", parameters_.num_threads, parameters_.num_threads);
  int bucket_points = 0;
  private_node.param("bucket_points", bucket_points, 0);
  if (bucket_points < 0) {
    NODELET_ERROR("parameter bucket_points must be >= 0 (got %d): using 0 (automatic)",
                  bucket_points);
    bucket_points = 0;
  }
  parameters_.bucket_points = static_cast<std::size_t>(bucket_points);
  private_node.param("grid", parameters_.grid_buckets, parameters_.grid_buckets);
  readViewpoint(private_node);
  private_node.param("queue_size", queue_size_, queue_size_);
  if (queue_size_ < 1) {
    NODELET_ERROR("parameter queue_size must be >= 1 (got %d): using 1", queue_size_);
    queue_size_ = 1;
  }
  private_node.param("latch", latch_, latch_);
  private_node.param("skip_if_busy", skip_if_busy_, skip_if_busy_);
}

void MedialScaffoldReconstructionNodelet::readViewpoint(ros::NodeHandle &private_node) {
  // Without the parameter the library takes the cloud's sensor origin for
  // organized clouds; a PointCloud2 carries none, so that is the frame's origin.
  if (!private_node.hasParam("viewpoint"))
    return;
  std::vector<double> viewpoint;
  if (!private_node.getParam("viewpoint", viewpoint) || viewpoint.size() != 3 ||
      !std::all_of(viewpoint.begin(), viewpoint.end(),
                   [](double coordinate) { return std::isfinite(coordinate); })) {
    NODELET_ERROR("parameter viewpoint must be a list of three numbers [x, y, z] in the cloud's "
                  "frame: ignored");
    return;
  }
  parameters_.viewpoint = std::array<double, 3>{viewpoint[0], viewpoint[1], viewpoint[2]};
}

void MedialScaffoldReconstructionNodelet::onInit() {
  ros::NodeHandle &node = getNodeHandle();
  ros::NodeHandle &private_node = getPrivateNodeHandle();
  readParameters(private_node);

  const std::string parameters_error = parameters_.validate();
  if (!parameters_error.empty())
    NODELET_ERROR("invalid parameters, every cloud will be refused until they are fixed: %s",
                  parameters_error.c_str());

  mesh_publisher_ = node.advertise<pcl_msgs::PolygonMesh>("mesh", 1, latch_);
  mesh_marker_publisher_ = node.advertise<visualization_msgs::Marker>("mesh_marker", 1, latch_);
  boundary_marker_publisher_ =
      node.advertise<visualization_msgs::Marker>("boundary_marker", 1, latch_);

  // roscpp never runs one subscriber's callback twice at once, so a cloud
  // arriving during meshing would wait in the queue. To drop it instead the
  // callback must run concurrently (on the manager's multi-threaded queue)
  // and return at once while another call is meshing.
  ros::SubscribeOptions options;
  options.init<sensor_msgs::PointCloud2>(
      "input", static_cast<std::uint32_t>(queue_size_),
      [this](const sensor_msgs::PointCloud2ConstPtr &message) { cloudCallback(message); });
  options.allow_concurrent_callbacks = skip_if_busy_;
  cloud_subscriber_ =
      skip_if_busy_ ? getMTNodeHandle().subscribe(options) : node.subscribe(options);

  std::string viewpoint = "the frame's origin for organized clouds";
  if (parameters_.viewpoint)
    viewpoint = "[" + std::to_string((*parameters_.viewpoint)[0]) + ", " +
                std::to_string((*parameters_.viewpoint)[1]) + ", " +
                std::to_string((*parameters_.viewpoint)[2]) + "]";
  NODELET_INFO(
      "meshing clouds from %s into %s, %s and %s (rho %g, fill_holes %d, use_normals "
      "%s, threads %d, bucket_points %zu, grid %d, viewpoint %s, queue_size %d, latch "
      "%s, skip_if_busy %s)",
      cloud_subscriber_.getTopic().c_str(), mesh_publisher_.getTopic().c_str(),
      mesh_marker_publisher_.getTopic().c_str(), boundary_marker_publisher_.getTopic().c_str(),
      parameters_.rho, parameters_.fill_holes_max_edges, parameters_.use_normals ? "true" : "false",
      parameters_.num_threads, parameters_.bucket_points, parameters_.grid_buckets,
      viewpoint.c_str(), queue_size_, latch_ ? "true" : "false", skip_if_busy_ ? "true" : "false");
}

void MedialScaffoldReconstructionNodelet::cloudCallback(
    const sensor_msgs::PointCloud2ConstPtr &message) {
  const Clock::time_point received = Clock::now();
  if (skip_if_busy_ && busy_.exchange(true)) {
    const std::size_t dropped = ++dropped_clouds_;
    NODELET_WARN_THROTTLE(5.0,
                          "skip_if_busy: dropped the cloud of %.3f s (frame '%s') while meshing "
                          "the previous one (%zu dropped so far)",
                          message->header.stamp.toSec(), message->header.frame_id.c_str(), dropped);
    return;
  }
  std::string report;
  bool meshed = false;
  try {
    meshed = meshAndPublish(*message, received, report);
  } catch (const std::exception &error) {
    // Say, out of memory copying a huge cloud: that cloud is lost, not the node.
    report = "cloud of " + std::to_string(message->header.stamp.toSec()) + " s (frame '" +
             message->header.frame_id + "') not meshed: " + error.what();
  }
  // Free before the line is logged: whoever reads it may send the next cloud.
  busy_ = false;
  if (meshed)
    NODELET_INFO("%s", report.c_str());
  else
    NODELET_ERROR("%s", report.c_str());
}

bool MedialScaffoldReconstructionNodelet::meshAndPublish(const sensor_msgs::PointCloud2 &message,
                                                         Clock::time_point received,
                                                         std::string &report) {
  pcl::PCLPointCloud2 cloud;
  pcl_conversions::toPCL(message, cloud);
  const ros_bridge::MeshingOutcome outcome = ros_bridge::meshCloud(cloud, parameters_);
  const std::size_t point_count = static_cast<std::size_t>(message.width) * message.height;
  char line[512];
  if (!outcome.error.empty()) {
    std::snprintf(line, sizeof line,
                  "cloud of %.3f s (frame '%s', %ux%u = %zu points) not meshed: ",
                  message.header.stamp.toSec(), message.header.frame_id.c_str(), message.width,
                  message.height, point_count);
    report = line + outcome.error;
    return false;
  }
  if (!outcome.warning.empty())
    NODELET_WARN_ONCE("%s", outcome.warning.c_str());

  // The mesh carries the message's own cloud, so every field rides along.
  pcl_msgs::PolygonMeshPtr mesh(new pcl_msgs::PolygonMesh);
  mesh->header = message.header;
  mesh->cloud = message;
  mesh->polygons.resize(outcome.polygons.size());
  for (std::size_t t = 0; t < outcome.polygons.size(); ++t)
    mesh->polygons[t].vertices.assign(outcome.polygons[t].vertices.begin(),
                                      outcome.polygons[t].vertices.end());
  mesh_publisher_.publish(mesh);
  const Clock::time_point mesh_published = Clock::now();

  publishMarkers(message.header, cloud, outcome);
  const Clock::time_point markers_published = Clock::now();

  const double to_mesh = secondsBetween(received, mesh_published);
  std::snprintf(line, sizeof line,
                "cloud %ux%u (%zu points, %zu finite), frame '%s': %zu triangles, %zu boundary "
                "loops; mesh published %.3f s after receipt (library %.3f s, conversion and "
                "publishing %.3f s), markers %.3f s",
                message.width, message.height, point_count, outcome.finite_points,
                message.header.frame_id.c_str(), outcome.polygons.size(),
                outcome.boundary_loops.size(), to_mesh, outcome.library_seconds,
                to_mesh - outcome.library_seconds, secondsBetween(received, markers_published));
  report = line;
  return true;
}

void MedialScaffoldReconstructionNodelet::publishMarkers(
    const std_msgs::Header &header, const pcl::PCLPointCloud2 &cloud,
    const ros_bridge::MeshingOutcome &outcome) {
  // Marker arrays are big (three points per triangle): build them only for
  // someone listening, or for a latched topic's later listeners.
  if (latch_ || mesh_marker_publisher_.getNumSubscribers() > 0) {
    visualization_msgs::MarkerPtr marker =
        makeMarker(header, "pcl_ms_mesh", visualization_msgs::Marker::TRIANGLE_LIST);
    marker->scale.x = marker->scale.y = marker->scale.z = 1.0;
    // Grey where the cloud has no colour.
    marker->color.r = marker->color.g = marker->color.b = 0.8f;
    fillMarker(ros_bridge::triangleListGeometry(cloud, outcome.polygons), *marker);
    mesh_marker_publisher_.publish(marker);
  }
  if (latch_ || boundary_marker_publisher_.getNumSubscribers() > 0) {
    visualization_msgs::MarkerPtr marker =
        makeMarker(header, "pcl_ms_boundary", visualization_msgs::Marker::LINE_LIST);
    // Lines as wide as the median circumradius (about the point spacing)
    // stand out at any scale of cloud.
    marker->scale.x = outcome.median_circumradius > 0 ? outcome.median_circumradius : 0.001;
    marker->color.b = 1.0f; // blue, as the paper draws boundaries
    fillMarker(ros_bridge::boundaryLineGeometry(cloud, outcome.boundary_loops), *marker);
    boundary_marker_publisher_.publish(marker);
  }
}

} // namespace pcl_ms

PLUGINLIB_EXPORT_CLASS(pcl_ms::MedialScaffoldReconstructionNodelet, nodelet::Nodelet)
