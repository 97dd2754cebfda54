#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
#
# Installs the Debian (bookworm) packages pcl_ms needs to build and test.
# Does nothing, quickly, when they are all installed already. Installing
# needs root; as another user it lists what is missing and exits 1.
set -euo pipefail

PACKAGES=(
  build-essential
  cmake
  pkg-config
  libpcl-dev
  libcgal-dev
  libeigen3-dev
  libflann-dev
  libboost-dev
  libgtest-dev
  libtbb-dev
  libgmp-dev
  libmpfr-dev
  # pcl_ms_reconstruct_mpi and its tests (mpirun); without them the tool is
  # not built.
  openmpi-bin
  libopenmpi-dev
  # Off-screen pictures (src/tools/render_mesh.cpp): Debian's VTK draws
  # through GLX only, so headless machines get a private Xvfb, and Mesa's
  # software OpenGL (llvmpipe, loaded at run time) does the drawing. libpng
  # checks pictures before VTK reads them.
  xvfb
  libgl1-mesa-dri
  libglx-mesa0
  libpng-dev
  # scripts/sanitizers.sh: clang 14 with its sanitizer runtimes and libFuzzer.
  clang-14
  libclang-rt-14-dev
  libfuzzer-14-dev
)
# ROS 1 as Debian ships it (cmake/pcl_ms_ros.cmake): the nodelet and node,
# pcd_to_pointcloud for the demo, rostest for the ROS tests, RViz. Without
# them the library still builds and the rostests are reported as skipped;
# PCL_MS_INSTALL_ROS=0 leaves them out.
ROS_PACKAGES=(
  ros-core-dev
  libnodeletlib-dev
  libnodeletlib-tools
  libnodelet-dev
  libpcl-ros-dev
  pcl-ros-tools
  libpcl-conversions-dev
  libpcl-msgs-dev
  libvisualization-msgs-dev
  python3-rostest
  python3-rospy
  python3-sensor-msgs
  python3-pcl-msgs
  python3-visualization-msgs
  python3-rosgraph-msgs
  rviz
)
if [[ "${PCL_MS_INSTALL_ROS:-1}" != "0" ]]; then
  PACKAGES+=("${ROS_PACKAGES[@]}")
fi

missing=()
for package in "${PACKAGES[@]}"; do
  status="$(dpkg-query -W -f='${db:Status-Status}' "${package}" 2>/dev/null || true)"
  if [[ "${status}" != "installed" ]]; then
    missing+=("${package}")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install_deps: all ${#PACKAGES[@]} required packages are installed"
  exit 0
fi

echo "install_deps: missing packages: ${missing[*]}"
if [[ "$(id -u)" -ne 0 ]]; then
  echo "install_deps: not running as root, cannot install them." >&2
  echo "install_deps: run this script as root, or install them yourself:" >&2
  echo "  sudo apt-get update && sudo apt-get install -y --no-install-recommends ${missing[*]}" >&2
  exit 1
fi

export DEBIAN_FRONTEND=noninteractive
apt-get update
apt-get install -y --no-install-recommends "${missing[@]}"
echo "install_deps: installed ${missing[*]}"
