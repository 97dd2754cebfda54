#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Usage: killed_rank.sh BUILD_DIR MPIEXEC RANKS INPUT [options...]
# One rank killed (SIGKILL) in the middle of a run: the job must end within
# seconds with a non-zero status, no rank left behind, no mesh written.
set -euo pipefail
build=$1 mpiexec=$2 ranks=$3 input=$4
shift 4
source "$(dirname "${BASH_SOURCE[0]}")/job_setup.sh"

# Each rank records its process id, then runs the tool.
"$mpiexec" "${mpirun_flags[@]}" -np "$ranks" bash -c \
  'echo $$ > "$3/pid.$OMPI_COMM_WORLD_RANK"; exec "$0" "$1" "$2" -q "${@:4}"' \
  "$build/pcl_ms_reconstruct_mpi" "$input" "$work/out.ply" "$work" "$@" \
  > "$work/log.txt" 2>&1 &
job=$!
victim=$((ranks - 1))
for _ in $(seq 100); do
  [[ -s $work/pid.$victim ]] && break
  sleep 0.1
done
[[ -s $work/pid.$victim ]] || { cat "$work/log.txt"; echo "FAIL: rank $victim never started"; exit 1; }
sleep 1 # inside the buckets
pids=$(cat "$work"/pid.*)
kill -KILL "$(cat "$work/pid.$victim")" ||
  { cat "$work/log.txt"; echo "FAIL: rank $victim had already exited"; exit 1; }
killed_at=$SECONDS
status=0
wait "$job" || status=$?
took=$((SECONDS - killed_at))
cat "$work/log.txt"
[[ $status != 0 ]] || { echo "FAIL: mpirun exited with 0 after a rank was killed"; exit 1; }
((took <= 10)) || { echo "FAIL: the job took $took s to end after the kill"; exit 1; }
# mpirun may return while the last ranks are being reaped: a short grace.
for pid in $pids; do
  for _ in $(seq 50); do
    kill -0 "$pid" 2> /dev/null || break
    sleep 0.1
  done
  if kill -0 "$pid" 2> /dev/null; then
    echo "FAIL: process $pid still runs 5 s after mpirun ended"
    exit 1
  fi
done
[[ ! -e $work/out.ply ]] || { echo "FAIL: a mesh was written"; exit 1; }
echo "rank $victim killed: the job ended with status $status within $took s"
