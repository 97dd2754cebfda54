# SPDX-License-Identifier: GPL-3.0-or-later
# Sourced by the MPI test scripts: mpirun's flags for this machine and a
# work directory removed on exit.
# --oversubscribe: more ranks than the 2 cores; mpirun refuses root (CI) unless told.
mpirun_flags=(--oversubscribe)
[[ $(id -u) == 0 ]] && mpirun_flags+=(--allow-run-as-root)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
