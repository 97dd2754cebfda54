#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Usage: awkward_cloud.sh BUILD_DIR MPIEXEC RANKS BINARY_PCD
# The ranks prepare the records of their own parts together: exact
# duplicates in other ranks' parts, NaN records and a far stray point must
# give one process's mesh and counts. A cloud with too few distinct points
# must fail on every rank with one process's reason and exit status.
set -euo pipefail
build=$1 mpiexec=$2 ranks=$3 input=$4
source "$(dirname "${BASH_SOURCE[0]}")/job_setup.sh"

python3 - "$input" "$work" << 'PYTHON'
import math, struct, sys
source, work = sys.argv[1], sys.argv[2]
data = open(source, 'rb').read()
start = data.index(b'DATA binary\n') + len(b'DATA binary\n')
records = [data[i:i + 12] for i in range(start, len(data), 12)]
nan = struct.pack('<3f', math.nan, 0.0, 0.0)
awkward = records[:]
awkward[100] = nan                       # NaN records in the first part
awkward += records[::97]                 # duplicates, in the last part
awkward.insert(len(records) // 2, nan)   # and in the middle
awkward.append(struct.pack('<3f', 40.0, -30.0, 25.0))  # a lone far stray point

def write(path, points):
    header = ('# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\n'
              'SIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH %d\nHEIGHT 1\n'
              'VIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA binary\n' % (len(points), len(points)))
    open(path, 'wb').write(header.encode() + b''.join(points))

write(work + '/awkward.pcd', awkward)
# Two distinct points, repeated, and a NaN: spread over every rank's part.
a, b = struct.pack('<3f', 0, 0, 0), struct.pack('<3f', 1, 2, 3)
write(work + '/too_few.pcd', [a, b, nan, a, a, b, b, a, b])
PYTHON

READ_IN_PARTS=1 bash "$(dirname "${BASH_SOURCE[0]}")/same_mesh.sh" "$build" "$mpiexec" "$ranks" \
  "$work/awkward.pcd" -bucket_points 4000
counts() { sed 's/\x1b\[[0-9;]*m//g' | grep -E '^ *(input points|invalid points|duplicates|far points)'; }
"$build/pcl_ms_reconstruct" "$work/awkward.pcd" "$work/one.ply" -bucket_points 4000 |
  counts > "$work/one_counts.txt"
"$mpiexec" "${mpirun_flags[@]}" -np "$ranks" "$build/pcl_ms_reconstruct_mpi" \
  "$work/awkward.pcd" "$work/ranks.ply" -bucket_points 4000 | counts > "$work/ranks_counts.txt"
cat "$work/ranks_counts.txt"
grep -qE 'duplicates merged +371$' "$work/ranks_counts.txt" ||
  { echo "FAIL: expected 371 duplicates merged"; exit 1; }
diff "$work/one_counts.txt" "$work/ranks_counts.txt" ||
  { echo "FAIL: the ranks counted otherwise than one process"; exit 1; }

status=0
"$build/pcl_ms_reconstruct" "$work/too_few.pcd" "$work/one.ply" 2> "$work/one_error.txt" ||
  status=$?
[[ $status == 3 ]] || { echo "FAIL: one process exited with $status, expected 3"; exit 1; }
record_rank_exits "$build/pcl_ms_reconstruct_mpi" "$work/too_few.pcd" "$work/out.ply"
cat "$work/stderr.txt"
[[ -e $work/out.ply ]] && { echo "FAIL: a mesh was written"; exit 1; }
diff <(sed 's/\x1b\[[0-9;]*m//g' "$work/one_error.txt") \
  <(sed 's/\x1b\[[0-9;]*m//g' "$work/stderr.txt") ||
  { echo "FAIL: the ranks gave another reason than one process, or more than once"; exit 1; }
expect_rank_exits 3 "reconstruction failed"
echo "too few points: all $ranks ranks exited with 3, with one process's reason"
