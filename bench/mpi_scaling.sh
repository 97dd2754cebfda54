#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
#
# pcl_ms_reconstruct_mpi on 1, 2 and 4 ranks against pcl_ms_reconstruct with
# 2 threads, on a uniform sampling of the bunny (bench_buckets' points:
# seed 20241122 + size). Prints wall time, each rank's and the job's peak
# resident memory (rank 0 first: the ranks read the binary PCD in parts,
# mesh their own buckets and seam zones and finish the surface in parts;
# rank 0 writes the runs as the ranks send them), and whether every
# mesh is byte-identical to the single-process one. Not part of ctest: 10M
# points take about 6 minutes on two cores. -work DIR (created if missing)
# keeps the cloud and each run's log there.
#
# Usage: bench/mpi_scaling.sh [-build DIR] [-points N] [-ranks "1 2 4"]
#                             [-bucket_points M] [-work DIR] [-mesh PATH]
set -euo pipefail

build=build points=10000000 ranks="1 2 4" bucket_points=0 work=""
mesh=../shared/data/stanford_bunny/reconstruction/bun_zipper.ply
[[ -e $mesh ]] || mesh=data/bun_zipper.ply
while (($#)); do
  case $1 in
  -build) build=$2 ;;
  -points) points=$2 ;;
  -ranks) ranks=$2 ;;
  -bucket_points) bucket_points=$2 ;;
  -work) work=$2 ;;
  -mesh) mesh=$2 ;;
  *) echo "unknown option $1" >&2; exit 1 ;;
  esac
  shift 2
done
if [[ -z $work ]]; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
else
  mkdir -p "$work"
fi
mpirun_flags=(--oversubscribe)
[[ $(id -u) == 0 ]] && mpirun_flags+=(--allow-run-as-root)
options=(-bucket_points "$bucket_points")
strip_colours() { sed 's/\x1b\[[0-9;]*m//g'; }

cloud=$work/cloud_$points.pcd
[[ -e $cloud ]] || "$build/sample_surface_cloud" "$mesh" "$points" "$cloud"

# One process, 2 threads: GNU time's wall seconds and peak RSS (KB).
/usr/bin/time -f "%e %M" -o "$work/time_one.txt" \
  "$build/pcl_ms_reconstruct" "$cloud" "$work/one.ply" -threads 2 "${options[@]}" 2>&1 |
  strip_colours > "$work/one.log"
read -r one_seconds one_kb < "$work/time_one.txt"
buckets=$(awk '$1 == "buckets" && $2 ~ /^[0-9]+$/ {print $2}' "$work/one.log")
seams=$(awk '$1 == "seam" && $2 == "zones" {print $3}' "$work/one.log")
triangles=$(awk '$1 == "triangles" {print $2}' "$work/one.log")
printf '%s points, %s buckets, %s seam zones, %s triangles (%s)\n\n' \
  "$points" "$buckets" "$seams" "$triangles" "$(date -u +%F)"
printf '| run | wall time | peak RSS per rank | peak RSS, all ranks | same mesh |\n'
printf '|---|---|---|---|---|\n'
printf '| pcl_ms_reconstruct, 2 threads | %.1f s | %.0f MB | %.0f MB | (reference) |\n' \
  "$one_seconds" "$((one_kb / 1024))" "$((one_kb / 1024))"

for n in $ranks; do
  /usr/bin/time -f "%e" -o "$work/time_$n.txt" \
    mpirun "${mpirun_flags[@]}" -np "$n" "$build/pcl_ms_reconstruct_mpi" "$cloud" \
    "$work/ranks_$n.ply" -threads 1 "${options[@]}" 2>&1 | strip_colours > "$work/ranks_$n.log"
  seconds=$(cat "$work/time_$n.txt")
  # The tool's own table: rank, peak RSS (MB), reconstruct (s), sent, received.
  peaks=$(awk '/^Ranks:/ {on = 1; next} on && $1 ~ /^[0-9]+$/ {printf "%s%.0f", sep, $2; sep = " / "}' \
    "$work/ranks_$n.log")
  total=$(awk '/peak RSS, all ranks/ {printf "%.0f", $5}' "$work/ranks_$n.log")
  same=no
  cmp -s "$work/one.ply" "$work/ranks_$n.ply" && same=yes
  printf '| %s rank%s, 1 thread each | %.1f s | %s MB | %s MB | %s |\n' \
    "$n" "$([[ $n == 1 ]] || echo s)" "$seconds" "$peaks" "$total" "$same"
  rm -f "$work/ranks_$n.ply"
done
