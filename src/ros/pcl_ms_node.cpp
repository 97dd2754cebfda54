// SPDX-License-Identifier: GPL-3.0-or-later
// pcl_ms_node: runs pcl_ms/MedialScaffoldReconstructionNodelet in a process
// of its own (the pcl_ros pattern), with the node's name, namespace,
// remappings and private parameters.
#include <nodelet/loader.h>
#include <ros/ros.h>

#include <string>
#include <vector>

int main(int argc, char **argv) {
  ros::init(argc, argv, "pcl_ms_node");
  nodelet::Loader loader;
  const nodelet::M_string remappings = ros::names::getRemappings();
  const nodelet::V_string nodelet_arguments(argv + 1, argv + argc);
  if (!loader.load(ros::this_node::getName(), "pcl_ms/MedialScaffoldReconstructionNodelet",
                   remappings, nodelet_arguments)) {
    ROS_FATAL("could not load pcl_ms/MedialScaffoldReconstructionNodelet: is the pcl_ms package "
              "on ROS_PACKAGE_PATH and its build directory on CMAKE_PREFIX_PATH (source "
              "<build>/pcl_ms_ros_setup.bash)?");
    return 1;
  }
  ros::spin();
  return 0;
}
