#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Usage: unshared_input.sh BUILD_DIR MPIEXEC RANKS BINARY_PCD
# No shared filesystem: only rank 0 sees the input (the others run where a
# relative path finds nothing). Rank 0 must then read the whole file itself
# and the mesh must be the single-process one, byte for byte; where every
# rank sees it, each must read a part.
set -euo pipefail
build=$1 mpiexec=$2 ranks=$3 input=$4
source "$(dirname "${BASH_SOURCE[0]}")/job_setup.sh"

mkdir "$work/rank0" "$work/elsewhere"
cp "$input" "$work/rank0/cloud.pcd"
"$build/pcl_ms_reconstruct" "$input" "$work/one_process.ply" -q -bucket_points 4000
for place in unshared shared; do
  "$mpiexec" "${mpirun_flags[@]}" -np "$ranks" bash -c \
    'if [[ $OMPI_COMM_WORLD_RANK == 0 || $3 == shared ]]; then cd "$1/rank0"; else cd "$1/elsewhere"; fi
     exec "$0" cloud.pcd "$2" -bucket_points 4000' \
    "$build/pcl_ms_reconstruct_mpi" "$work" "$work/$place.ply" "$place" > "$work/colour.txt" 2>&1 ||
    { cat "$work/colour.txt"; echo "FAIL: the $place run exited with $?"; exit 1; }
  sed 's/\x1b\[[0-9;]*m//g' "$work/colour.txt" > "$work/$place.log"
  cmp "$work/one_process.ply" "$work/$place.ply" ||
    { echo "FAIL: the $place run gave a different mesh from one process"; exit 1; }
done
grep -q 'points, 1 part\]' "$work/unshared.log" ||
  { cat "$work/unshared.log"; echo "FAIL: rank 0 did not read the whole file alone"; exit 1; }
grep -q "points, $ranks parts\]" "$work/shared.log" ||
  { cat "$work/shared.log"; echo "FAIL: the ranks did not read $ranks parts"; exit 1; }
echo "same mesh with the input on rank 0 only and on all $ranks ranks"
