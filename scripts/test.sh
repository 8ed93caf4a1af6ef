#!/usr/bin/env bash
# Sets up what is missing, builds, and runs the WHOLE test suite (every CTest
# label: unit, gpu, hardcase, render, ui). GUI tests need an X server: when no
# DISPLAY is set the suite runs under Xvfb. Extra arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
ctest_cmd=(ctest --preset default --timeout 900 "$@")
if [ -z "${DISPLAY:-}" ]; then
  exec xvfb-run -a -s "-screen 0 1920x1080x24" "${ctest_cmd[@]}"
else
  exec "${ctest_cmd[@]}"
fi
