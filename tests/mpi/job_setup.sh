# SPDX-License-Identifier: GPL-3.0-or-later
# Sourced by the MPI test scripts: mpirun's flags for this machine and a
# work directory removed on exit.
# --oversubscribe: more ranks than the 2 cores; mpirun refuses root (CI) unless told.
mpirun_flags=(--oversubscribe)
[[ $(id -u) == 0 ]] && mpirun_flags+=(--allow-run-as-root)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# record_rank_exits PROGRAM ARGS...: runs PROGRAM ARGS on $ranks ranks;
# each rank writes its exit status to $work/exit.RANK, the job's output
# goes to $work/stdout.txt and $work/stderr.txt.
record_rank_exits() {
  "$mpiexec" "${mpirun_flags[@]}" -np "$ranks" bash -c \
    'work=$1; shift; "$@"; echo "$?" > "$work/exit.$OMPI_COMM_WORLD_RANK"' \
    record "$work" "$@" > "$work/stdout.txt" 2> "$work/stderr.txt" || true
}

# expect_rank_exits STATUS WHAT: every rank exited with STATUS (WHAT names it).
expect_rank_exits() {
  local rank code
  for ((rank = 0; rank < ranks; ++rank)); do
    code=$(cat "$work/exit.$rank" 2> /dev/null || echo none)
    [[ $code == "$1" ]] || { echo "FAIL: rank $rank exited with $code, expected $1 ($2)"; exit 1; }
  done
}
