#!/usr/bin/env bash
# Installs exactly the Debian 12 packages LightCull Studio needs to build, run
# and test. Idempotent: packages already present are not touched, and nothing
# is downloaded from anywhere but the machine's configured apt sources.
set -euo pipefail

PACKAGES=(
  # toolchain
  cmake ninja-build g++ pkg-config git
  # packaging: cpack -G DEB computes Depends with dpkg-shlibdeps and file(1)
  dpkg-dev file
  # culling core
  libglm-dev libopenmesh-dev nlohmann-json3-dev libcli11-dev libpng-dev zlib1g-dev
  # glTF 2.0 scenes (tinygltf's header, compiled into the library)
  libtinygltf-dev
  # Vulkan: headers, loader, lavapipe, shader compiler, validation in tests
  libvulkan-dev mesa-vulkan-drivers glslang-tools glslang-dev spirv-tools
  vulkan-validationlayers
  # RenderDoc: the in-application capture API's header and library (run
  # --renderdoc-capture) and its Python replay module (check --capture)
  librenderdoc-dev librenderdoc python3-renderdoc
  # studio: Qt 5 and VTK 9 (Debian's VTK Qt module is built on Qt 5)
  qtbase5-dev libvtk9-dev libvtk9-qt-dev
  # tests and benchmarks: GoogleTest, Google Benchmark, a virtual X server
  libgtest-dev libbenchmark-dev xvfb xauth x11-utils imagemagick
  # hostile-input runs: clang with libFuzzer and the sanitizer runtimes
  # (scripts/fuzz.sh), llvm-symbolizer for readable sanitizer stacks
  clang-14 libclang-rt-14-dev llvm-14
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

if ! command -v apt-get >/dev/null 2>&1; then
  echo "install-deps: apt-get not found. LightCull Studio targets Debian 12; install these packages with your system's package manager:" >&2
  printf '  %s\n' "${missing[@]}" >&2
  exit 1
fi

SUDO=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    SUDO=(sudo)
  else
    echo "install-deps: not root and sudo is not available; as root run: apt-get install ${missing[*]}" >&2
    exit 1
  fi
fi

echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${SUDO[@]}" apt-get update -q
"${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
