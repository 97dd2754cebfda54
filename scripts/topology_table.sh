#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
#
# Meshes the clouds of known topology (bench/make_synthetic_clouds) with
# pcl_ms and CGAL's AFSR and prints a markdown table of each result's
# topology beside the truth (bench/topology_table.py).
#
#   scripts/topology_table.sh BUILD_DIR OUT_DIR
#
# BUILD_DIR must hold make_synthetic_clouds and pcl_ms_compare. The clouds go
# to OUT_DIR/clouds/, each cloud's meshes, pictures and results.csv to
# OUT_DIR/<name>/. Progress goes to stderr, the table to stdout.
set -euo pipefail

usage="usage: scripts/topology_table.sh BUILD_DIR OUT_DIR"
if [[ $# -ne 2 || $1 == -h || $1 == --help ]]; then
  echo "$usage" >&2
  exit 1
fi
fail() {
  echo "error: $*" >&2
  exit 2
}

build_dir=$1
out_dir=$2
[[ -d $build_dir ]] || fail "build directory '$build_dir' not found ($usage)"
for program in make_synthetic_clouds pcl_ms_compare; do
  [[ -x $build_dir/$program ]] || fail "$build_dir/$program not found: build it first"
done
command -v python3 >/dev/null || fail "python3 not found"
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

mkdir -p "$out_dir"
"$build_dir/make_synthetic_clouds" -out "$out_dir/clouds" >&2
# The first column of truth.csv is the name; the cloud is <name>.pcd.
tail -n +2 "$out_dir/clouds/truth.csv" | cut -d, -f1 | while read -r name; do
  echo "[$name] pcl_ms_compare -methods pcl_ms,afsr" >&2
  status=0
  "$build_dir/pcl_ms_compare" "$out_dir/clouds/$name.pcd" -methods pcl_ms,afsr -q \
    -picture_size 480 -out "$out_dir/$name" >&2 || status=$?
  [[ $status -eq 0 ]] || echo "warning: pcl_ms_compare exited with status $status on $name" >&2
done
python3 "$repo/bench/topology_table.py" "$out_dir"
