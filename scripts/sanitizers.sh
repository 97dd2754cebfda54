#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
#
# The sanitizer and fuzzing jobs. CI runs this after scripts/test.sh; it uses
# its own build directories and leaves build/ alone.
#
#  1. build-asan (clang 14: AddressSanitizer + UndefinedBehaviorSanitizer,
#     with libFuzzer coverage): the CTest tests except the rendering and
#     comparison suites (VTK drawing through Mesa's software OpenGL, which is
#     third-party code we do not instrument and which is slow under ASan),
#     downstream_consumer (an install test: it builds a consumer without the
#     sanitizer flags) and the large-cloud tests listed below (minutes each
#     under ASan). Then each fuzz target in tests/fuzz for
#     FUZZ_SECONDS (default 30) from its seed corpus in tests/fuzz/corpus.
#  2. build-tsan (gcc: ThreadSanitizer): the threaded tests on small clouds
#     (Finish, TimeLimit, the fuzz corpus, the small Buckets tests).
#
# Any sanitizer report or fuzz finding fails the script. Findings are saved
# as build-asan/fuzz-findings/<target>/crash-* for reproduction:
#   build-asan/fuzz_<target> <file>
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

FUZZ_SECONDS="${FUZZ_SECONDS:-30}"
JOBS="${JOBS:-$(nproc)}"
bash scripts/install_deps.sh

# ---------------------------------------------------------------------------
# AddressSanitizer + UndefinedBehaviorSanitizer (and the fuzz targets).
# The library is a shared object linked with --no-undefined: clang puts the
# sanitizer runtime in it only with -shared-libsan, and the programs then
# find that runtime through an rpath.
runtime_dir="$(dirname "$(clang++-14 -print-file-name=libclang_rt.asan-x86_64.so)")"
asan_flags="-O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all"
asan_link="-fsanitize=address,undefined -shared-libsan -Wl,-rpath,${runtime_dir}"
# Open MPI's own allocations are reported as leaks when it runs under LSan:
# pcl_ms_reconstruct_mpi is left out here; its units are the ones the other
# bucketed tests run.
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Sanitize \
  -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
  -DCMAKE_C_FLAGS="${asan_flags}" \
  -DCMAKE_CXX_FLAGS="${asan_flags} -fsanitize=fuzzer-no-link" \
  -DCMAKE_EXE_LINKER_FLAGS="${asan_link}" -DCMAKE_SHARED_LINKER_FLAGS="${asan_link}" \
  -DPCL_MS_BUILD_BENCH=OFF -DPCL_MS_BUILD_FUZZ=ON -DPCL_MS_BUILD_MPI=OFF
cmake --build build-asan -j"${JOBS}"

# Leaks are reported too: a test that leaks fails. halt_on_error stops at
# the first report so that it is not lost in later noise.
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:abort_on_error=1:strict_string_checks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$(pwd)/tests/sanitizers/lsan.supp:print_suppressions=0"
# Left out, besides rendering and the install test: the tests that mesh
# large clouds (the bunny several times, 300,000-point samplings, buckets),
# minutes each under ASan. Their code paths run here on smaller clouds, and
# the threaded ones under ThreadSanitizer below.
heavy='Bunny\..*|Determinism\..*|BucketLoops\..*|Buckets\.(SameMeshForOneTwoAndEightThreads'
heavy+='|GridSeamsMatchTheOnePieceMesh|MedianSplitSeamsMatchTheOnePieceMesh)'
heavy+='|InitialTriangles\.AreKeptAndTheSurfaceIsCompletedAroundThem|PclClass\.BucketSettersReachTheCore'
heavy+='|App\.BucketsWithProgressAndSummary|Scaffold\.EdgeGraphHoldsOnlyTheCandidatesOfPassOne'
# Pictures are rendering too: the GL driver's allocations, which LeakSanitizer
# cannot see into, are reported as leaks.
pictures='MedialAxisTool\.CompareDrawsItBesideTheSurface|AppSeams\.CompareDrawsSeams'
# The nodelet's rostest is left out too: ROS's own nodelet manager, which
# loads the plugin, is not built with ASan, and ASan refuses to start inside
# it. The same nodelet code runs under ASan in rostest.mesh_node (our node).
ctest --test-dir build-asan --output-on-failure -j2 \
  -E "^(downstream_consumer|Render.*|CompareApp\..*|${pictures}|rostest\.mesh_nodelet|${heavy})$"

mkdir -p build-asan/fuzz-findings
for fuzzer in build-asan/fuzz_*; do
  target="$(basename "${fuzzer}")"
  target="${target#fuzz_}"
  corpus="tests/fuzz/corpus/${target}"
  work="build-asan/fuzz-corpus/${target}" # new inputs stay out of the repository
  findings="build-asan/fuzz-findings/${target}"
  mkdir -p "${work}" "${findings}"
  echo "sanitizers: fuzzing ${target} for ${FUZZ_SECONDS} s"
  # libFuzzer's link puts libstdc++ before the ASan runtime, which is
  # harmless (libstdc++ does not replace malloc) but trips ASan's check.
  ASAN_OPTIONS="${ASAN_OPTIONS}:verify_asan_link_order=0" \
    "${fuzzer}" -max_total_time="${FUZZ_SECONDS}" -timeout=30 -rss_limit_mb=4096 \
    -max_len=4096 -print_final_stats=1 -artifact_prefix="${findings}/" \
    "${work}" "${corpus}" 2>&1 | tail -n 25
  # pipefail already stops on libFuzzer's exit code; the artifact check
  # also names the input to reproduce.
  # Slow units (slow-unit-*) are reported, not failures.
  if compgen -G "${findings}/[clot][roei][a-z]*-*" > /dev/null; then
    echo "sanitizers: fuzz finding in ${target}: $(ls "${findings}")" >&2
    exit 1
  fi
done

# ---------------------------------------------------------------------------
# ThreadSanitizer on the threaded tests.
tsan_flags="-O1 -g -fno-omit-frame-pointer -fsanitize=thread"
cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=Sanitize \
  -DCMAKE_C_FLAGS="${tsan_flags}" -DCMAKE_CXX_FLAGS="${tsan_flags}" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=thread" \
  -DPCL_MS_BUILD_BENCH=OFF
# Set before the build: CMake runs the test binary to list its tests.
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:history_size=7:suppressions=$(pwd)/tests/sanitizers/tsan.supp"
cmake --build build-tsan -j"${JOBS}" --target pcl_ms_tests pcl_ms_core_tests
# Threaded tests (and the huge-page regions, freed across threads): the
# same mesh for 1, 2 and 8 threads in buckets, in one piece, with the medial
# axis and with local scales: 1.5 minutes together since the loops tell TSan
# how TBB orders them (threads.h). Before, TSan reported and then
# suppressed every such access: Finish.SameSurfaceForAnyNumberOfThreads took
# 155 s, now under 1 s. The fuzz corpus brings bucketed runs on 2 threads;
# BucketExchange runs the bunny as 2, 3 and 24 processes sharing buckets;
# TwistsInParts finishes Moebius bands held in parts, HolesInParts and
# CutsInParts bunny patches on two processes (the bunny patch on many
# splits of the other finishing-in-parts tests takes 11 minutes under
# TSan, EdgesInParts' updates for fillings and cuts 10 minutes: they are
# left out); the small
# PrepareTogether and BucketsByOwner tests and the
# shared_reconstruct corpus prepare and mesh clouds in parts (threads
# standing in for processes), in buckets on 2 threads too. The bunny
# prepared or meshed in parts takes 2 to 10 minutes a test under TSan (TBB's
# sorts and loops) and is left out.
./build-tsan/pcl_ms_core_tests \
  --gtest_filter='Finish.*:TwistsInParts.*:EdgesInParts.Runs*:SidesInParts.PointSlices*:HolesInParts.Nothing*:HolesInParts.Slices*:CutsInParts.Runs*:Threads.*:HugePages.*:PrepareTogether.TooFew*:BucketsByOwner.FewPoints*:BucketsByOwner.NoBucket*:BucketsByOwner.OnePiece*'
./build-tsan/pcl_ms_tests --gtest_filter='TimeLimit*.*:FuzzCorpus.*:BucketExchange.*:Buckets.AutomaticChoiceDependsOnTheCloudSizeOnly:Buckets.InvalidBucketParametersAreRejected:Buckets.OneUnitKeepsOnlyTrianglesOnItsCorePoints:Buckets.ZonesMeshedAsReadyGiveTheOneThreadMesh:Buckets.SameMeshForOneTwoAndEightThreads:Determinism.SameInputSameMeshAcrossRunsAndThreads:MedialAxis.SameFromReconstructWhateverTheOrderAndThreads:LocalScale.BucketsAgreeWithOnePieceOnANonUniformCloud'
echo "sanitizers: ASan/UBSan tests, fuzzing and TSan tests passed"
