#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Usage: initial_triangles.sh BUILD_DIR MPIEXEC RANKS INPUT FOREIGN_CLOUD MODE
# -initial across ranks. The initial triangles are pcl_ms_reconstruct's
# mesh of INPUT with -rho 3 (unlike the final mesh): rank 0 meshes the cloud
# with them in one piece and writes what pcl_ms_reconstruct writes
# (same_mesh.sh). In fixed mode, the mesh of FOREIGN_CLOUD, whose vertices
# are not points of INPUT, must make every rank exit with 1, as
# pcl_ms_reconstruct does, naming the vertex.
set -euo pipefail
build=$1 mpiexec=$2 ranks=$3 input=$4 foreign=$5 mode=$6
here=$(dirname "${BASH_SOURCE[0]}")
source "$here/job_setup.sh"
"$build/pcl_ms_reconstruct" "$input" "$work/initial.ply" -q -rho 3
ONE_PIECE=1 bash "$here/same_mesh.sh" "$build" "$mpiexec" "$ranks" "$input" \
  -initial "$work/initial.ply" -initial_mode "$mode"
[[ $mode == fixed ]] || exit 0

"$build/pcl_ms_reconstruct" "$foreign" "$work/foreign.ply" -q
record_rank_exits "$build/pcl_ms_reconstruct_mpi" "$input" "$work/out.ply" \
  -initial "$work/foreign.ply"
grep -q "^error: -initial: vertex .* is not a point of" "$work/stderr.txt" ||
  { cat "$work/stderr.txt"; echo "FAIL: no error naming the foreign vertex"; exit 1; }
expect_rank_exits 1 "bad arguments"
[[ -e $work/out.ply ]] && { echo "FAIL: a mesh was written"; exit 1; }
echo "a foreign initial mesh in fixed mode: every rank exited with 1"
