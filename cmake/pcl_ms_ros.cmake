# SPDX-License-Identifier: GPL-3.0-or-later
#
# ROS 1 support, included by the top-level CMakeLists.txt.
#
# Targets:
#   pcl_ms_ros_bridge        static, ROS-free: PointCloud2-shaped clouds in, mesh and
#                            marker arrays out (src/ros/cloud_meshing.cpp); always built
#   pcl_ms_ros_bridge_tests  its GoogleTest suite (PCL_MS_BUILD_TESTS)
#   pcl_ms_nodelet           the nodelet plugin  -> <build>/ros/lib/libpcl_ms_nodelet.so
#   pcl_ms_node              the standalone node -> <build>/ros/lib/pcl_ms/pcl_ms_node
#
# Debian's ROS 1 has no catkin workspace: roscpp comes from pkg-config, the
# rest (nodelet, pluginlib, message headers) from plain header and library
# look-ups. <build>/ros is laid out like a catkin devel space (.catkin marker,
# lib/, lib/pcl_ms/), so with <build>/ros on CMAKE_PREFIX_PATH pluginlib finds
# the plugin library and roslaunch/rosrun the node, wherever the build is.
# <build>/pcl_ms_ros_setup.bash sets that up.

set(PCL_MS_BUILD_ROS AUTO CACHE STRING
  "Build the ROS 1 nodelet and node: AUTO (if ROS is found), ON (fail without ROS) or OFF")
set_property(CACHE PCL_MS_BUILD_ROS PROPERTY STRINGS AUTO ON OFF)

add_library(pcl_ms_ros_bridge STATIC "${PROJECT_SOURCE_DIR}/src/ros/cloud_meshing.cpp")
target_include_directories(pcl_ms_ros_bridge PUBLIC "${PROJECT_SOURCE_DIR}/src/ros")
target_link_libraries(pcl_ms_ros_bridge PUBLIC pcl_ms PRIVATE pcl_ms_metrics)
pcl_ms_set_warnings(pcl_ms_ros_bridge)

if(PCL_MS_BUILD_TESTS)
  add_executable(pcl_ms_ros_bridge_tests "${PROJECT_SOURCE_DIR}/tests/ros/test_cloud_meshing.cpp")
  target_link_libraries(pcl_ms_ros_bridge_tests PRIVATE pcl_ms_ros_bridge pcl_io
                                                        GTest::gtest_main)
  target_compile_definitions(pcl_ms_ros_bridge_tests PRIVATE
    PCL_MS_DATA_DIR="${PROJECT_SOURCE_DIR}/data")
  pcl_ms_set_warnings(pcl_ms_ros_bridge_tests)
  gtest_discover_tests(pcl_ms_ros_bridge_tests
    TEST_PREFIX "ros_bridge."
    DISCOVERY_TIMEOUT 120
    PROPERTIES TIMEOUT 300)
endif()

# Without the node the rostests cannot run: one CTest entry says so and
# counts as skipped, not as passed or failed.
function(pcl_ms_skip_rostests reason)
  message(STATUS "ROS nodelet and node: ${reason}")
  if(PCL_MS_BUILD_TESTS)
    add_test(NAME rostest.skipped
      COMMAND ${CMAKE_COMMAND} -E echo "rostests skipped: ${reason}")
    # Exit status 0 plus this expression marks the test skipped.
    set_tests_properties(rostest.skipped PROPERTIES SKIP_REGULAR_EXPRESSION "rostests skipped")
  endif()
endfunction()

if(PCL_MS_BUILD_ROS STREQUAL "OFF")
  pcl_ms_skip_rostests("not built (PCL_MS_BUILD_ROS=OFF)")
  return()
endif()

# --- Finding Debian's ROS 1 ------------------------------------------------
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(PCL_MS_ROSCPP QUIET IMPORTED_TARGET roscpp)
endif()
find_path(PCL_MS_NODELET_INCLUDE_DIR nodelet/nodelet.h)
find_library(PCL_MS_NODELET_LIBRARY nodeletlib)
find_path(PCL_MS_PLUGINLIB_INCLUDE_DIR pluginlib/class_list_macros.hpp PATH_SUFFIXES pluginlib)
find_path(PCL_MS_CLASS_LOADER_INCLUDE_DIR class_loader/class_loader.hpp PATH_SUFFIXES class_loader)
find_library(PCL_MS_CLASS_LOADER_LIBRARY class_loader)
# Debian's class_loader is the ROS 2 one, whose headers include rcpputils and
# rcutils. pluginlib's own CMake configuration would need ament's Python.
find_path(PCL_MS_RCPPUTILS_INCLUDE_DIR rcpputils/shared_library.hpp PATH_SUFFIXES rcpputils)
find_path(PCL_MS_RCUTILS_INCLUDE_DIR rcutils/types.h PATH_SUFFIXES rcutils)
find_library(PCL_MS_RCPPUTILS_LIBRARY rcpputils)
find_library(PCL_MS_RCUTILS_LIBRARY rcutils)
find_path(PCL_MS_PCL_CONVERSIONS_INCLUDE_DIR pcl_conversions/pcl_conversions.h)
find_path(PCL_MS_PCL_MSGS_INCLUDE_DIR pcl_msgs/PolygonMesh.h)
find_path(PCL_MS_SENSOR_MSGS_INCLUDE_DIR sensor_msgs/PointCloud2.h)
find_path(PCL_MS_VISUALIZATION_MSGS_INCLUDE_DIR visualization_msgs/Marker.h)
find_program(PCL_MS_ROSTEST rostest)

set(_pcl_ms_ros_missing)
if(NOT PCL_MS_ROSCPP_FOUND)
  list(APPEND _pcl_ms_ros_missing "roscpp (pkg-config)")
endif()
foreach(_variable IN ITEMS NODELET_INCLUDE_DIR NODELET_LIBRARY PLUGINLIB_INCLUDE_DIR
                           CLASS_LOADER_INCLUDE_DIR CLASS_LOADER_LIBRARY
                           RCPPUTILS_INCLUDE_DIR RCUTILS_INCLUDE_DIR
                           RCPPUTILS_LIBRARY RCUTILS_LIBRARY
                           PCL_CONVERSIONS_INCLUDE_DIR PCL_MSGS_INCLUDE_DIR
                           SENSOR_MSGS_INCLUDE_DIR VISUALIZATION_MSGS_INCLUDE_DIR)
  if(NOT PCL_MS_${_variable})
    list(APPEND _pcl_ms_ros_missing "${_variable}")
  endif()
endforeach()
if(_pcl_ms_ros_missing)
  if(PCL_MS_BUILD_ROS STREQUAL "ON")
    message(FATAL_ERROR "PCL_MS_BUILD_ROS=ON but ROS 1 is incomplete, missing: "
      "${_pcl_ms_ros_missing} (bash scripts/install_deps.sh installs it on Debian)")
  endif()
  pcl_ms_skip_rostests("not built, ROS 1 not installed (missing: ${_pcl_ms_ros_missing})")
  return()
endif()
message(STATUS "ROS nodelet and node: building (roscpp ${PCL_MS_ROSCPP_VERSION})")

# One interface target; imported, so its include directories count as system
# headers and ROS's own warnings stay out of ours.
add_library(pcl_ms_ros1 INTERFACE IMPORTED)
set_target_properties(pcl_ms_ros1 PROPERTIES
  INTERFACE_INCLUDE_DIRECTORIES
    "${PCL_MS_NODELET_INCLUDE_DIR};${PCL_MS_PLUGINLIB_INCLUDE_DIR};${PCL_MS_CLASS_LOADER_INCLUDE_DIR};${PCL_MS_RCPPUTILS_INCLUDE_DIR};${PCL_MS_RCUTILS_INCLUDE_DIR};${PCL_MS_PCL_CONVERSIONS_INCLUDE_DIR};${PCL_MS_PCL_MSGS_INCLUDE_DIR};${PCL_MS_SENSOR_MSGS_INCLUDE_DIR};${PCL_MS_VISUALIZATION_MSGS_INCLUDE_DIR}"
  INTERFACE_LINK_LIBRARIES
    "PkgConfig::PCL_MS_ROSCPP;${PCL_MS_NODELET_LIBRARY};${PCL_MS_CLASS_LOADER_LIBRARY};${PCL_MS_RCPPUTILS_LIBRARY};${PCL_MS_RCUTILS_LIBRARY}")

set(PCL_MS_ROS_PREFIX "${CMAKE_BINARY_DIR}/ros")
# catkin_find (used by roslaunch and rosrun) searches only prefixes marked so.
file(WRITE "${PCL_MS_ROS_PREFIX}/.catkin" "")

add_library(pcl_ms_nodelet SHARED "${PROJECT_SOURCE_DIR}/src/ros/medial_scaffold_reconstruction_nodelet.cpp")
target_link_libraries(pcl_ms_nodelet PRIVATE pcl_ms_ros_bridge pcl_ms_ros1)
set_target_properties(pcl_ms_nodelet PROPERTIES LIBRARY_OUTPUT_DIRECTORY "${PCL_MS_ROS_PREFIX}/lib")
pcl_ms_set_warnings(pcl_ms_nodelet)

add_executable(pcl_ms_node "${PROJECT_SOURCE_DIR}/src/ros/pcl_ms_node.cpp")
target_link_libraries(pcl_ms_node PRIVATE pcl_ms_ros1)
set_target_properties(pcl_ms_node PROPERTIES
  RUNTIME_OUTPUT_DIRECTORY "${PCL_MS_ROS_PREFIX}/lib/pcl_ms")
# The node loads the nodelet through pluginlib; build both together.
add_dependencies(pcl_ms_node pcl_ms_nodelet)
pcl_ms_set_warnings(pcl_ms_node)

# Sourced by users and by the rostests: the repository is the package, the
# build's ros/ prefix holds its binaries.
set(PCL_MS_ROS_SETUP "${CMAKE_BINARY_DIR}/pcl_ms_ros_setup.bash")
file(WRITE "${PCL_MS_ROS_SETUP}"
  "# Generated by pcl_ms's CMake: makes the pcl_ms ROS package usable from this build.\n"
  "export ROS_PACKAGE_PATH=\"${PROJECT_SOURCE_DIR}\${ROS_PACKAGE_PATH:+:\${ROS_PACKAGE_PATH}}\"\n"
  "# rospack looks in <prefix>/share of CMAKE_PREFIX_PATH, /usr when it is unset: keep it.\n"
  "export CMAKE_PREFIX_PATH=\"${PCL_MS_ROS_PREFIX}:\${CMAKE_PREFIX_PATH:-/usr}\"\n")

if(PCL_MS_BUILD_TESTS)
  if(NOT PCL_MS_ROSTEST)
    message(FATAL_ERROR "ROS 1 was found but rostest was not (Debian package python3-rostest)")
  endif()
  set(PCL_MS_ROS_TEST_ENVIRONMENT
    "ROS_PACKAGE_PATH=${PROJECT_SOURCE_DIR};CMAKE_PREFIX_PATH=${PCL_MS_ROS_PREFIX}:/usr;ROS_HOME=${CMAKE_BINARY_DIR}/ros_home")
  file(GLOB PCL_MS_ROSTEST_FILES CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/tests/ros/*.test")
  file(GLOB PCL_MS_LAUNCH_FILES CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/launch/*.launch")
  # Every launch file loads and names nodes that exist (demo.launch is not
  # run by the tests: it publishes forever).
  add_test(NAME roslaunch_check
    COMMAND /usr/bin/python3 "${PROJECT_SOURCE_DIR}/tests/ros/check_launch_files.py"
            ${PCL_MS_LAUNCH_FILES} ${PCL_MS_ROSTEST_FILES})
  set_tests_properties(roslaunch_check PROPERTIES
    TIMEOUT 120
    ENVIRONMENT "${PCL_MS_ROS_TEST_ENVIRONMENT}")
  foreach(_test_file IN LISTS PCL_MS_ROSTEST_FILES)
    get_filename_component(_name "${_test_file}" NAME_WE)
    # rostest starts its own roscore on a free port; logs stay in the build.
    # Not --text: with it rostest exits 0 even when a test fails.
    add_test(NAME rostest.${_name}
      COMMAND "${PCL_MS_ROSTEST}" "${_test_file}" "data_dir:=${PROJECT_SOURCE_DIR}/data")
    set_tests_properties(rostest.${_name} PROPERTIES
      TIMEOUT 300
      FAIL_REGULAR_EXPRESSION "RESULT: FAIL"
      ENVIRONMENT "${PCL_MS_ROS_TEST_ENVIRONMENT}")
  endforeach()
endif()
