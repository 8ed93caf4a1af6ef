#!/usr/bin/env bash
# Installs what is missing, then configures and builds LightCull Studio into
# build/ (the CMake preset "default"). Used by studio.sh and test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset default >/dev/null
cmake --build --preset default -j"$(nproc)"
