#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
#
# Regenerates the benchmark table in README.md ("Results") and
# docs/bunny_side_by_side.png: runs pcl_ms_compare on each data set below and
# assembles the table from the results.csv files (bench/readme_table.py).
#
#   bench/make_readme_table.sh [BUILD_DIR] [SHARED_DATA_DIR]
#
# BUILD_DIR (default build) must hold pcl_ms_compare; SHARED_DATA_DIR
# (default ../shared/data) is the data collection described by its
# MANIFEST.md. Both are taken relative to the current directory. Outputs of
# each run stay in BUILD_DIR/readme_table/<data set>/.
set -euo pipefail

usage="usage: bench/make_readme_table.sh [BUILD_DIR] [SHARED_DATA_DIR]"
if [[ $# -gt 2 || ${1:-} == -h || ${1:-} == --help ]]; then
  echo "$usage" >&2
  exit 1
fi
fail() {
  echo "error: $*" >&2
  exit 2
}

build_dir=${1:-build}
shared=${2:-../shared/data}
[[ -d $build_dir ]] || fail "build directory '$build_dir' not found ($usage)"
[[ -d $shared ]] || fail "shared data directory '$shared' not found ($usage)"
build_dir=$(cd "$build_dir" && pwd)
shared=$(cd "$shared" && pwd)
compare=$build_dir/pcl_ms_compare
[[ -x $compare ]] || fail "$compare not found: build the project first (cmake --build $build_dir)"
command -v python3 >/dev/null || fail "python3 not found"

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
helper=bench/readme_table.py
work=$build_dir/readme_table

for file in data/bunny.pcd data/bun_zipper.ply "$shared/stanford_bunny/data/bun000.ply" \
  "$shared/cgal/meshes/fandisk.off" "$shared/libigl-tutorial-data/camelhead.off" \
  "$shared/vcglib-trimeshinfo/moebius_big.ply" "$shared/pcl/milk.pcd" \
  "$shared/pcl/table_scene_mug_stereo_textured.pcd"; do
  [[ -f $file ]] || fail "data file $file not found"
done

rm -rf "$work"
mkdir -p "$work/inputs"
start=$SECONDS

# Meshes whose vertices are the cloud: one float32 PLY is both cloud and GT.
python3 "$helper" mesh2ply "$shared/cgal/meshes/fandisk.off" "$work/inputs/fandisk.ply"
python3 "$helper" mesh2ply "$shared/libigl-tutorial-data/camelhead.off" "$work/inputs/camelhead.ply"
python3 "$helper" mesh2ply "$shared/vcglib-trimeshinfo/moebius_big.ply" "$work/inputs/moebius.ply"
python3 "$helper" sample "$work/inputs/moebius.ply" "$work/inputs/moebius_10k.xyz" 10000 1
[[ -x $build_dir/make_synthetic_clouds ]] ||
  fail "$build_dir/make_synthetic_clouds not found: build the project first"
"$build_dir/make_synthetic_clouds" -out "$work/inputs/synthetic" >/dev/null

printf 'id\tlabel\tinput\twhy\tgt\trecall\tstatus\n' >"$work/datasets.tsv"

# run_set ID LABEL INPUT_TEXT WHY CLOUD GT(or "") RECALL(yes/no)
run_set() {
  local id=$1 label=$2 text=$3 why=$4 cloud=$5 gt=$6 recall=$7 status=0
  echo "[$label] pcl_ms_compare $cloud${gt:+ -gt $gt}"
  "$compare" "$cloud" ${gt:+-gt "$gt"} -out "$work/$id" -picture_size 480 -q || status=$?
  [[ $status -eq 0 ]] || echo "warning: pcl_ms_compare exited with status $status on $label" >&2
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$id" "$label" "$text" "$why" "${gt:+yes}" "$recall" \
    "$status" >>"$work/datasets.tsv"
}

run_set bunny "Bunny" \
  "\`data/bunny.pcd\` (the vertices of \`bun_zipper.ply\`), GT \`data/bun_zipper.ply\`" \
  "The standard case: a clean, dense scan, open only at five holes in its base, whose GT has exactly these vertices." \
  data/bunny.pcd data/bun_zipper.ply yes
run_set bun000 "Raw scan bun000" \
  "\`stanford_bunny/data/bun000.ply\` (one range scan, front view), GT \`data/bun_zipper.ply\`" \
  "A raw single-view scan with scanner noise; it lies in the GT's frame, so distances apply (GT → mesh is large: the scan sees one side only), but its points are not the GT's vertices, so recall does not." \
  "$shared/stanford_bunny/data/bun000.ply" data/bun_zipper.ply no
run_set fandisk "Fandisk (CAD)" \
  "\`cgal/meshes/fandisk.off\`, its vertices; GT the mesh" \
  "CAD part with sharp feature edges and corners (closed, genus 0)." \
  "$work/inputs/fandisk.ply" "$work/inputs/fandisk.ply" yes
run_set camelhead "Camel head (open)" \
  "\`libigl-tutorial-data/camelhead.off\`, its vertices; GT the mesh" \
  "Open surface: a disk with one boundary loop at the neck cut, which a method should keep open." \
  "$work/inputs/camelhead.ply" "$work/inputs/camelhead.ply" yes
run_set moebius "Möbius strip, vertices" \
  "\`vcglib-trimeshinfo/moebius_big.ply\`, its vertices; GT the mesh" \
  "Non-orientable surface as stored: the strip is only three edges wide, so sampling is sparse across it." \
  "$work/inputs/moebius.ply" "$work/inputs/moebius.ply" yes
run_set moebius_10k "Möbius strip, 10k sample" \
  "10,000 area-uniform points on the same mesh (Python \`random.Random(1)\`); GT the mesh" \
  "The same non-orientable strip sampled densely, so the surface and not the sampling decides; recall does not apply." \
  "$work/inputs/moebius_10k.xyz" "$work/inputs/moebius.ply" no
run_set milk "Milk carton (noisy)" \
  "\`pcl/milk.pcd\`, a partial real scan of a milk carton from PCL's test data; no GT" \
  "A noisy real scan (visible depth noise and striping, one side only); topology only." \
  "$shared/pcl/milk.pcd" "" no
run_set sphere_gradient "Sphere, density 1:25" \
  "8,000 points on the unit sphere whose density falls 25-fold from one pole to the other (\`make_synthetic_clouds\`, fixed seed); no GT mesh" \
  "Non-uniform sampling: one global length breaks the sparse half apart; the truth is one closed component with no boundary loop." \
  "$work/inputs/synthetic/sphere_gradient_25.pcd" "" no
run_set mug "Kinect frame (mug)" \
  "\`pcl/table_scene_mug_stereo_textured.pcd\`, an organized 640 x 480 depth frame from PCL's test data (NaN where there is no depth); no GT" \
  "What a robot's depth camera sees: density falling with range, depth jumps and noise; pcl_ms orients it towards the sensor, the frame's origin." \
  "$shared/pcl/table_scene_mug_stereo_textured.pcd" "" no

picture=docs/bunny_side_by_side.png
if [[ -f $work/bunny/side_by_side.png ]]; then
  mkdir -p docs
  cp "$work/bunny/side_by_side.png" "$picture"
  size=$(wc -c <"$picture")
  if [[ $size -gt 512000 ]]; then
    echo "warning: $picture is $size bytes; lower -picture_size in this script" >&2
  fi
else
  echo "warning: no side_by_side.png for the bunny; README written without the picture" >&2
  picture=
fi
# The Kinect frame's picture, linked from the README's viewpoint section.
if [[ -f $work/mug/side_by_side.png ]]; then
  cp "$work/mug/side_by_side.png" docs/kinect_mug_side_by_side.png
else
  echo "warning: no side_by_side.png for the Kinect frame" >&2
fi
python3 "$helper" table "$work" README.md $picture
echo "README.md table rewritten in $((SECONDS - start)) s; outputs in $work"
