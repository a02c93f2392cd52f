#!/usr/bin/env bash
# Obelisk set-up, build and run. One entry point for the README and CI.
#
#   ./setup.sh demo   install missing packages, build, render the main demo headless
#   ./setup.sh test   install missing packages, build, run the whole test suite
#   ./setup.sh deps | build
#
# Options: --sanitize address|thread|undefined  (builds into build-<sanitizer>/)
#          --build-dir DIR
set -euo pipefail
cd "$(dirname "$0")"

cmd=${1:-demo}
[ $# -gt 0 ] && shift
sanitize=""
build_dir=""
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --sanitize) sanitize=$2; shift 2 ;;
    --build-dir) build_dir=$2; shift 2 ;;
    *) extra+=("$1"); shift ;;
  esac
done
[ -n "$build_dir" ] || build_dir=build${sanitize:+-$sanitize}

packages=(
  cmake make gcc clang pkg-config
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers
  glslang-dev spirv-tools libspirv-cross-c-shared-dev
  libcglm-dev libstb-dev libassimp-dev assimp-testmodels libcjson-dev
  libcmocka-dev gnuplot-nox libglfw3-dev
)

deps() {
  local missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "setup: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo=sudo
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
}

build() {
  local cfg=(-S . -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo)
  [ -n "$sanitize" ] && cfg+=(-DOB_SANITIZE="$sanitize" -DCMAKE_C_COMPILER=clang)
  cmake "${cfg[@]}" >/dev/null
  cmake --build "$build_dir" -j"$(nproc)"
}

# lavapipe and the loader warn about a missing XDG_RUNTIME_DIR on bare machines.
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}

case "$cmd" in
  deps) deps ;;
  build) deps; build ;;
  demo)
    deps; build
    "$build_dir"/bin/obelisk-mirror --frames 60 --out "$build_dir"/obelisk-mirror.png "${extra[@]}" ;;
  test)
    deps; build
    ctest --test-dir "$build_dir" --output-on-failure -j"$(nproc)" "${extra[@]}" ;;
  *) echo "usage: $0 demo|test|deps|build [--sanitize address|thread|undefined]" >&2; exit 2 ;;
esac
