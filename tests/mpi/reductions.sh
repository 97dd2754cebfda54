#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Usage: reductions.sh CHECK_PROGRAM MPIEXEC RANKS
# Runs tests/mpi/reductions_check.cpp on RANKS ranks: each rank must get
# the same bits from the group's minimum and maximum (NaN, signed zeros).
set -euo pipefail
check=$1 mpiexec=$2 ranks=$3
source "$(dirname "${BASH_SOURCE[0]}")/job_setup.sh"
"$mpiexec" "${mpirun_flags[@]}" -np "$ranks" "$check" < /dev/null
echo "$ranks ranks: the same minimum and maximum on each"
