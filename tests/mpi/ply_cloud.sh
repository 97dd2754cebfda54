#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Usage: ply_cloud.sh BUILD_DIR MPIEXEC RANKS MESH_PLY [options...]
# The vertices of a binary PLY mesh, written as a PLY cloud with PCL's camera
# element after them, are read by the ranks in parts and meshed as by
# pcl_ms_reconstruct (same_mesh.sh). With ESTIMATE_NORMALS=K the mesh is
# first made by pcl_ms_reconstruct with normals from K neighbours, so that
# the cloud's records carry nx ny nz curvature before x y z. With
# VIEWPORT="W H" the camera's viewport makes the cloud W x H, organized.
set -euo pipefail
build=$1 mpiexec=$2 ranks=$3 input=$4
shift 4
here=$(dirname "${BASH_SOURCE[0]}")
source "$here/job_setup.sh"
if [[ -n ${ESTIMATE_NORMALS:-} ]]; then
  "$build/pcl_ms_reconstruct" "$input" "$work/with_normals.ply" -q \
    -estimate_normals "$ESTIMATE_NORMALS"
  input=$work/with_normals.ply
fi
python3 "$here/ply_cloud.py" "$input" "$work/cloud.ply" --camera ${VIEWPORT:-}
READ_IN_PARTS=1 bash "$here/same_mesh.sh" "$build" "$mpiexec" "$ranks" "$work/cloud.ply" "$@"
