#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
#
# Writes docs/ros_rviz_bunny.png: RViz showing the bunny's mesh and its blue
# boundary loops as launch/demo.launch publishes them. Runs on a private Xvfb
# with Mesa's software OpenGL, so it needs no display. Needs a build with ROS
# (default build/) and ImageMagick's `import`. Not part of the tests.
#
#   bash scripts/ros_rviz_screenshot.sh [BUILD_DIR] [OUTPUT_PNG]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

build_dir="${1:-build}"
output="${2:-docs/ros_rviz_bunny.png}"
if [[ ! -f "${build_dir}/pcl_ms_ros_setup.bash" ]]; then
  echo "ros_rviz_screenshot: ${build_dir} has no ROS build (configure with ROS installed)" >&2
  exit 1
fi
command -v import > /dev/null || { echo "ros_rviz_screenshot: needs ImageMagick (import)" >&2; exit 1; }

# shellcheck source=/dev/null
source "${build_dir}/pcl_ms_ros_setup.bash"
ROS_HOME="$(mktemp -d)"
export ROS_HOME
display=":$((50 + RANDOM % 40))"
# A master of our own on a free port, not a roscore someone else runs.
port="$((20000 + RANDOM % 20000))"
export ROS_MASTER_URI="http://localhost:${port}"
Xvfb "${display}" -screen 0 960x720x24 -nolisten tcp &
xvfb_pid=$!
launch_pid=""
cleanup() {
  if [[ -n "${launch_pid}" ]]; then
    # roslaunch runs in a process group of its own (setsid): end all of it.
    kill -INT -- "-${launch_pid}" 2> /dev/null || true
    timeout 20 tail --pid="${launch_pid}" -f /dev/null || kill -KILL -- "-${launch_pid}" 2> /dev/null || true
  fi
  kill "${xvfb_pid}" 2> /dev/null || true
  rm -rf "${ROS_HOME}"
}
trap cleanup EXIT

export DISPLAY="${display}" LIBGL_ALWAYS_SOFTWARE=1
setsid roslaunch -p "${port}" pcl_ms demo.launch rviz:=true > "${ROS_HOME}/demo.log" 2>&1 &
launch_pid=$!
# The boundary marker is latched: once it can be read, the bunny is meshed.
# rostopic fails at once while the master is still starting: retry.
meshed=false
for _ in $(seq 60); do
  if timeout 30 rostopic echo -n 1 /bunny_mesh/boundary_marker/header/frame_id &> /dev/null; then
    meshed=true
    break
  fi
  sleep 2
done
if [[ "${meshed}" != true ]]; then
  echo "ros_rviz_screenshot: no bunny mesh within 120 s; the launch's output:" >&2
  cat "${ROS_HOME}/demo.log" >&2
  exit 1
fi
# RViz needs a few more seconds to draw with software OpenGL.
sleep "${SETTLE_SECONDS:-8}"
import -window root "${output}"
echo "ros_rviz_screenshot: wrote ${output}"
