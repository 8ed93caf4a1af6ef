#!/usr/bin/env bash
# Builds the libFuzzer targets (clang-14, ASan+UBSan+fuzzer) in build-fuzz/
# (or $LIGHTCULL_FUZZ_BUILD_DIR) --
# only the culling library and tests/fuzz -- and runs each for a bounded time
# on a copy of its seed corpus (tests/fuzz/corpus/<target>/).
#
#   scripts/fuzz.sh [target...]      default: every target
#   LIGHTCULL_FUZZ_SECONDS=60        time per target (an upper bound)
#   LIGHTCULL_FUZZ_RUNS=20000        inputs per target, from -seed=1: CI runs the
#                                    same inputs every time (a random seed made it
#                                    red or green by luck; see docs/TESTING.md)
#   LIGHTCULL_FUZZ_JOBS=2            targets run side by side
#   LIGHTCULL_FUZZ_SEED=1            libFuzzer -seed (0: random; for hunting, not CI)
#   LIGHTCULL_FUZZ_BUILD_DIR=build-fuzz
#
# A crash, leak, sanitizer report or timeout fails the script; the input that
# caused it is kept in build-fuzz/artifacts/ (reproduce: build-fuzz/tests/fuzz/<target>
# <file>). Make every crash a regression test in tests/unit and fix it.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${LIGHTCULL_FUZZ_SECONDS:-60}"
jobs="${LIGHTCULL_FUZZ_JOBS:-2}"
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(fuzz_capture fuzz_gltf fuzz_camera_path fuzz_scene_json fuzz_mesh_obj fuzz_mesh_ply fuzz_mesh_off fuzz_mesh_stl)

bdir="${LIGHTCULL_FUZZ_BUILD_DIR:-build-fuzz}"
export bdir
cmake -S . -B "$bdir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
  -DLIGHTCULL_FUZZ=ON -DLIGHTCULL_TESTS=OFF -DLIGHTCULL_STUDIO=OFF -DLIGHTCULL_BENCHMARKS=OFF >/dev/null
cmake --build "$bdir" -j"$(nproc)" --target "${targets[@]}"

mkdir -p "$bdir"/corpus "$bdir"/artifacts "$bdir"/logs
run_one() {
  local t="$1" seconds="$2"
  local work="$bdir/corpus/$t"
  mkdir -p "$work"
  cp -n tests/fuzz/corpus/"$t"/* "$work"/ 2>/dev/null || true
  # Leak checks on: a leak in our code is a bug too (scripts/lsan.supp names
  # the third-party ones, OpenMesh's stream multiplexer among them).
  if ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0" \
     UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
     "$bdir"/tests/fuzz/"$t" "$work" -seed="${LIGHTCULL_FUZZ_SEED:-1}" -runs="${LIGHTCULL_FUZZ_RUNS:-20000}" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 \
       -max_len=16384 -print_final_stats=1 -artifact_prefix="$bdir/artifacts/$t-" \
       >"$bdir/logs/$t.log" 2>&1; then
    echo "fuzz: $t ok ($(grep -m1 -o 'stat::number_of_executed_units: *[0-9]*' "$bdir/logs/$t.log" | grep -o '[0-9]*$') runs in ${seconds}s)"
  else
    echo "fuzz: $t FAILED; log $bdir/logs/$t.log, input in $bdir/artifacts/" >&2
    tail -40 "$bdir/logs/$t.log" >&2
    return 1
  fi
}
export -f run_one
printf '%s\n' "${targets[@]}" | xargs -P "$jobs" -I{} bash -c 'run_one "$@"' _ {} "$seconds"
