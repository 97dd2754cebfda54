#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Usage: bench_reconstruct_options.sh BUILD_DIR DATA_DIR
# bench_reconstruct's -clouds, -threads, -afsr_up_to and -calls: an extra
# cloud gets its own table, every thread count its pcl_ms row (the same mesh,
# so the same triangle count) and its bare Delaunay row, AFSR runs only on
# inputs up to the limit, and the header says how many calls each child
# made; unusable options fail with one error line.
set -euo pipefail
build=$1 data=$2
bench=$build/bench_reconstruct
out=$(mktemp)
trap 'rm -f "$out"' EXIT
fail() { echo "FAIL: $*"; cat "$out"; exit 1; }

"$bench" -data "$data" -sizes none -clouds "$data/car6.pcd" -threads 1,2 -afsr_up_to 20000 \
  -calls 2 > "$out"
# The rows of one table: from its "== name" line to the next.
table() { awk -v name="$1" '/^== /{on = index($0, name) > 0} on' "$out"; }
# A method's row: its name, then its time in seconds.
triangles() { table "$1" | awk -v m="$2" '$0 ~ "^  " m " +[0-9]+\\.[0-9]+ " {print $NF}'; }
for name in "bunny vertices" "car6.pcd"; do
  table "$name" | grep -q . || fail "no table for $name"
  one=$(triangles "$name" "pcl_ms") two=$(triangles "$name" "pcl_ms 2 threads")
  [[ -n $one && $one == "$two" ]] || fail "$name: pcl_ms on 1 and 2 threads gave '$one' and '$two' triangles"
  table "$name" | grep -q '^  Delaunay 3D 2 threads  *[0-9]' || fail "$name: no 2-thread Delaunay row"
  table "$name" | grep -q 'pcl_ms 2 threads / Delaunay 3D 2 threads' ||
    fail "$name: no ratio against the 2-thread Delaunay"
done
grep -q '^Each child called its method 2 times' "$out" || fail "no line on the 2 calls"
table "car6.pcd" | grep -q '^  AFSR  *[0-9]' || fail "AFSR left out of car6 (10k points, limit 20,000)"
table "bunny vertices" | grep -q '^  AFSR' && fail "AFSR ran on the bunny (36k points, limit 20,000)"

expect_error() {
  local status=0
  "$bench" -data "$data" -sizes none "$@" > "$out" 2>&1 || status=$?
  [[ $status == 1 ]] || fail "'$*' exited with $status, expected 1"
  grep -q "^error: $expected" "$out" || fail "'$*' did not print 'error: $expected'"
}
expected="-clouds: " expect_error -clouds "$data/no_such_cloud.pcd"
expected="-threads: " expect_error -threads 0
expected="-afsr_up_to: " expect_error -afsr_up_to 1,2
expected="-calls: " expect_error -calls 0
expected="-repeat: " expect_error -repeat 2x
echo "bench_reconstruct options: ok"
