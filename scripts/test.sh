#!/usr/bin/env bash
# The README's test command and CI (.ci/run). Three stages, each timed:
#   1. build (preset default) and run the WHOLE test suite (every CTest label:
#      unit, gpu, hardcase, render, ui); GUI tests need an X server, so without
#      DISPLAY the suite runs under Xvfb. Extra arguments go to this ctest.
#   2. ASan+UBSan build (preset asan, build-asan/) and its `unit` and
#      `hardcase` tests, with third-party (Mesa/LLVM/validation layer) leak
#      reports suppressed by scripts/lsan.supp and nothing else.
#   3. the bounded libFuzzer runs (scripts/fuzz.sh, build-fuzz/).
#   4. the install: `cmake --install` of build/ into a temporary prefix, the
#      installed lightcull on a built-in and an installed example scene, the
#      installed studio's --screenshot, and `cpack -G DEB` with its Depends
#      checked and its payload run.
# LIGHTCULL_TEST_STAGES selects stages; the default is "1 2 3 4", or only "1"
# when ctest arguments are given (`scripts/test.sh -L unit` runs a subset).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -gt 0 ]; then default_stages="1"; else default_stages="1 2 3 4"; fi
stages="${LIGHTCULL_TEST_STAGES:-$default_stages}"
jobs="$(nproc)"

stage_time() { # name start
  echo "test.sh: $1 took $(( $(date +%s) - $2 )) s"
}
with_display() {
  if [ -z "${DISPLAY:-}" ]; then
    xvfb-run -a -s "-screen 0 1920x1080x24" "$@"
  else
    "$@"
  fi
}

if [[ " $stages " == *" 1 "* ]]; then
  t0=$(date +%s)
  scripts/build.sh
  stage_time "stage 1 build" "$t0"
  t1=$(date +%s)
  with_display ctest --preset default --timeout 900 "$@"
  stage_time "stage 1 tests (whole suite)" "$t1"
fi

if [[ " $stages " == *" 2 "* ]]; then
  t0=$(date +%s)
  scripts/install-deps.sh
  cmake --preset asan >/dev/null
  cmake --build --preset asan -j"$jobs"
  stage_time "stage 2 ASan+UBSan build" "$t0"
  t1=$(date +%s)
  # halt_on_error: the first report fails the test. The suppressions name
  # only third-party libraries (see the file).
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
  # fast_unwind_on_malloc=0: lavapipe and LLVM have no frame pointers, so the
  # fast unwinder stops inside them, and once the loader has unloaded them
  # (vkDestroyInstance) their frames cannot be attributed at exit. The slow
  # unwinder reaches the loader's own frames (libvulkan.so, still loaded),
  # which the suppressions name; our own leaks keep our frames and still fail.
  ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:fast_unwind_on_malloc=0" \
    ctest --test-dir build-asan -L '^unit$' --output-on-failure -j "$jobs" --timeout 900 --no-tests=error
  # Known gap (docs/TESTING.md): leak checking is off for the hard cases. At
  # exit, leaks are reported from blocks allocated by lavapipe / the validation
  # layer after the loader has unloaded them, so their stacks cannot be
  # attributed (or suppressed by library). Address and UB checks stay on.
  ASAN_OPTIONS="detect_leaks=0:abort_on_error=1" \
    ctest --test-dir build-asan -L '^hardcase$' --output-on-failure -j "$jobs" --timeout 900 --no-tests=error
  stage_time "stage 2 ASan+UBSan unit+hardcase tests" "$t1"
fi

if [[ " $stages " == *" 3 "* ]]; then
  t0=$(date +%s)
  scripts/fuzz.sh
  stage_time "stage 3 fuzzing (build + runs)" "$t0"
fi

if [[ " $stages " == *" 4 "* ]]; then
  t0=$(date +%s)
  [ -x build/app/cli/lightcull ] || scripts/build.sh
  prefix="$(mktemp -d "${TMPDIR:-/tmp}/lightcull-install.XXXXXX")"
  trap 'rm -rf "$prefix"' EXIT
  cmake --install build --prefix "$prefix" >/dev/null
  "$prefix/bin/lightcull" run --builtin atrium --width 320 --height 180 --out "$prefix/out-atrium"
  "$prefix/bin/lightcull" run --scene "$prefix/share/lightcull/scenes/stele_courtyard.json" --width 320 \
    --height 180 --out "$prefix/out-stele"
  "$prefix/bin/lightcull" run --builtin atrium --width 320 --height 180 --no-image-error \
    --shader "$prefix/share/lightcull/culling-examples/tiled_fixed.comp" --out "$prefix/out-custom"
  grep -q '"false_negatives": 0' "$prefix/out-custom/summary.json"
  with_display "$prefix/bin/lightcull-studio" --screenshot "$prefix/studio.png" --quit
  test -s "$prefix/studio.png"
  test -f "$prefix/share/applications/lightcull-studio.desktop"
  test -f "$prefix/share/icons/hicolor/scalable/apps/lightcull-studio.svg"
  # Every page an installed page links to is installed beside it.
  for page in $(grep -ho '](\([A-Za-z_]*\.md\)' "$prefix/share/doc/lightcull/"*.md | sed 's/^](//' | sort -u); do
    test -f "$prefix/share/doc/lightcull/$page" ||
      { echo "test.sh: the installed docs link to $page, which is not installed" >&2; exit 1; }
  done
  test -f "$prefix/share/doc/lightcull/ENGINES.md"
  (cd build && cpack -G DEB >/dev/null)
  deb="$(ls build/lightcull_*_*.deb | head -n1)"
  dpkg-deb -f "$deb" Depends | tee "$prefix/depends.txt"
  for need in mesa-vulkan-drivers libvulkan1 libqt5widgets5 libvtk9.1; do
    grep -q "$need" "$prefix/depends.txt" || { echo "test.sh: $deb does not depend on $need" >&2; exit 1; }
  done
  dpkg-deb -x "$deb" "$prefix/deb"
  "$prefix/deb/usr/bin/lightcull" run --builtin atrium --width 160 --height 90 --out "$prefix/out-deb"
  echo "test.sh: install: $prefix/bin and $deb ran"
  stage_time "stage 4 install and package" "$t0"
fi
