#!/usr/bin/env bash
# Sets up what is missing, builds, and opens LightCull Studio on its built-in
# default scene. Extra arguments go to the studio (e.g. --builtin forest).
# Without a display it says how to run under Xvfb instead.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
if [ -x build/app/studio/lightcull-studio ]; then
  exec build/app/studio/lightcull-studio --run "$@"
fi
# The studio is not part of this build: run the CLI on the default scene.
out=out/default-scene
build/app/cli/lightcull run --builtin atrium --out "$out" "$@"
echo "Outputs written to $(pwd)/$out (summary.json, tiles.csv, heatmap.png)"
