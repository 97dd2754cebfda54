#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Usage: same_mesh.sh BUILD_DIR MPIEXEC RANKS INPUT [options...]
# pcl_ms_reconstruct_mpi on RANKS ranks must write the same mesh, byte for
# byte, as pcl_ms_reconstruct with the same options. MESH_EXTENSION (default
# ply) picks the output format; READ_IN_PARTS=1 asks that every rank read its
# own part of the input; ONE_PIECE=1 expects a run in one piece (no seams).
set -euo pipefail
build=$1 mpiexec=$2 ranks=$3 input=$4
shift 4
source "$(dirname "${BASH_SOURCE[0]}")/job_setup.sh"
ext=${MESH_EXTENSION:-ply}

"$build/pcl_ms_reconstruct" "$input" "$work/one_process.$ext" -q "$@"
"$mpiexec" "${mpirun_flags[@]}" -np "$ranks" \
  "$build/pcl_ms_reconstruct_mpi" "$input" "$work/ranks.$ext" "$@" > "$work/colour.txt" 2>&1 ||
  { cat "$work/colour.txt"; echo "FAIL: pcl_ms_reconstruct_mpi exited with $?"; exit 1; }
# PCL's console colours its output even into a file.
sed 's/\x1b\[[0-9;]*m//g' "$work/colour.txt" > "$work/log.txt"

# The run must have been bucketed, with seams, or it proves nothing.
seams=$(awk '/seam zones/ {print $3}' "$work/log.txt")
if [[ ${ONE_PIECE:-0} == 1 ]]; then
  [[ -z $seams ]] || { cat "$work/log.txt"; echo "FAIL: expected one piece"; exit 1; }
  seams=0
elif [[ -z $seams || $seams -lt 3 ]]; then
  cat "$work/log.txt"
  echo "FAIL: expected at least 3 seam zones, got '${seams}'"
  exit 1
fi
if [[ ${READ_IN_PARTS:-0} == 1 ]]; then
  parts="$ranks parts"
  ((ranks == 1)) && parts="1 part"
  grep -q "points, $parts\]" "$work/log.txt" ||
    { cat "$work/log.txt"; echo "FAIL: the input was not read in $parts"; exit 1; }
fi
# Every rank reported its peak memory.
reported=$(grep -cE '^ *[0-9]+( +[0-9.]+){6} *$' "$work/log.txt" || true)
if [[ $reported != "$ranks" ]]; then
  cat "$work/log.txt"
  echo "FAIL: $reported rank rows in the summary, expected $ranks"
  exit 1
fi
if ! cmp "$work/one_process.$ext" "$work/ranks.$ext"; then
  echo "FAIL: $ranks ranks gave a different mesh from one process"
  exit 1
fi
echo "same mesh on $ranks ranks ($seams seam zones, $(stat -c %s "$work/ranks.$ext") bytes)"
