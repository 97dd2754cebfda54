#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Usage: bad_region.sh BUILD_DIR MPIEXEC RANKS BINARY_PCD_OR_PLY
# Each rank reads its own byte range of a binary PCD or PLY (a PLY mesh is
# first written as a cloud, its vertices alone). With the file's last
# records cut off, only the last rank's range is bad: that rank must say so
# (naming itself and the file), the others must not claim an error of their
# own, every rank must exit with 2 (file error), quickly, and no mesh may be
# written.
set -euo pipefail
build=$1 mpiexec=$2 ranks=$3 input=$4
source "$(dirname "${BASH_SOURCE[0]}")/job_setup.sh"

ext=${input##*.}
if [[ $ext == ply ]]; then
  python3 "$(dirname "${BASH_SOURCE[0]}")/ply_cloud.py" "$input" "$work/cloud.ply"
  input=$work/cloud.ply
fi
# 100 bytes fewer: part of the last record or records, none of the others'.
head -c $(($(stat -c %s "$input") - 100)) "$input" > "$work/cut.$ext"
started=$SECONDS
record_rank_exits "$build/pcl_ms_reconstruct_mpi" "$work/cut.$ext" "$work/out.ply" \
  -bucket_points 4000
took=$((SECONDS - started))
cat "$work/stderr.txt"
[[ -e $work/out.ply ]] && { echo "FAIL: a mesh was written"; exit 1; }
last=$((ranks - 1))
grep -q "^error: \(rank $last: \)\?.*cut.$ext: truncated ${ext^^} file" "$work/stderr.txt" ||
  { echo "FAIL: no 'error:' line from rank $last naming the file"; exit 1; }
if ((ranks > 1)) && grep -v "rank $last:" "$work/stderr.txt" | grep -q '^error:'; then
  echo "FAIL: a rank whose range is whole reported an error"
  exit 1
fi
grep -q 'Reconstructing' "$work/stdout.txt" && { echo "FAIL: meshing started"; exit 1; }
expect_rank_exits 2 "file error"
((took <= 20)) || { echo "FAIL: the job took $took s"; exit 1; }
echo "rank $last's range was cut short: all $ranks ranks exited with 2 within $took s"
