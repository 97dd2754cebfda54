#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Usage: corrupt_input.sh BUILD_DIR MPIEXEC RANKS BINARY_PCD
# A binary PCD cut off in the middle of its data: every rank must exit
# non-zero (each records its own exit status), and rank 0 must say why.
set -euo pipefail
build=$1 mpiexec=$2 ranks=$3 input=$4
source "$(dirname "${BASH_SOURCE[0]}")/job_setup.sh"

head -c $(($(stat -c %s "$input") / 2)) "$input" > "$work/truncated.pcd"
"$mpiexec" "${mpirun_flags[@]}" -np "$ranks" bash -c \
  '"$0" "$1" "$2" -bucket_points 4000; echo "$?" > "$3/exit.$OMPI_COMM_WORLD_RANK"' \
  "$build/pcl_ms_reconstruct_mpi" "$work/truncated.pcd" "$work/out.ply" "$work" \
  2> "$work/stderr.txt" || true
cat "$work/stderr.txt"
[[ -e $work/out.ply ]] && { echo "FAIL: a mesh was written"; exit 1; }
grep -q '^error: .*truncated.pcd' "$work/stderr.txt" ||
  { echo "FAIL: no 'error:' line naming the file"; exit 1; }
for ((rank = 0; rank < ranks; ++rank)); do
  [[ -e $work/exit.$rank ]] || { echo "FAIL: rank $rank did not exit"; exit 1; }
  code=$(cat "$work/exit.$rank")
  [[ $code == 2 ]] || { echo "FAIL: rank $rank exited with $code, expected 2 (file error)"; exit 1; }
done
# Without the wrapper, mpirun itself reports the failure.
status=0
"$mpiexec" "${mpirun_flags[@]}" -np "$ranks" "$build/pcl_ms_reconstruct_mpi" \
  "$work/truncated.pcd" "$work/out.ply" -q 2> /dev/null || status=$?
[[ $status != 0 ]] || { echo "FAIL: mpirun exited with 0"; exit 1; }
echo "all $ranks ranks exited with 2; mpirun with $status"
