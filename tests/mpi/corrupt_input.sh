#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Usage: corrupt_input.sh BUILD_DIR MPIEXEC RANKS BINARY_PCD
# A binary PCD cut off in the middle of its data: every rank must exit
# non-zero (each records its own exit status), and rank 0 must say why.
set -euo pipefail
build=$1 mpiexec=$2 ranks=$3 input=$4
source "$(dirname "${BASH_SOURCE[0]}")/job_setup.sh"

head -c $(($(stat -c %s "$input") / 2)) "$input" > "$work/truncated.pcd"
record_rank_exits "$build/pcl_ms_reconstruct_mpi" "$work/truncated.pcd" "$work/out.ply" \
  -bucket_points 4000
cat "$work/stderr.txt"
[[ -e $work/out.ply ]] && { echo "FAIL: a mesh was written"; exit 1; }
grep -q '^error: .*truncated.pcd' "$work/stderr.txt" ||
  { echo "FAIL: no 'error:' line naming the file"; exit 1; }
expect_rank_exits 2 "file error"
# Without the wrapper, mpirun itself reports the failure.
status=0
"$mpiexec" "${mpirun_flags[@]}" -np "$ranks" "$build/pcl_ms_reconstruct_mpi" \
  "$work/truncated.pcd" "$work/out.ply" -q 2> /dev/null || status=$?
[[ $status != 0 ]] || { echo "FAIL: mpirun exited with 0"; exit 1; }
echo "all $ranks ranks exited with 2; mpirun with $status"
