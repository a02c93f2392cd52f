#!/usr/bin/env bash
# Obelisk set-up, build and run. One entry point for the README and CI.
#
#   ./setup.sh demo   install missing packages, build, render the main demo headless
#   ./setup.sh test   install missing packages, then build and run the whole test
#                     suite three times: plain (build/), address+undefined
#                     sanitizers (build-address/) and thread sanitizer (build-thread/),
#                     then a minute of libFuzzer on each fuzz target (build-fuzz/).
#                     The plain suite also installs the build into
#                     build/package/prefix and builds and runs examples/ against
#                     it, out of tree (ctest label package, tests/package/)
#   ./setup.sh golden [NAME...]  install missing packages, build, and regenerate
#                     the golden images tests/golden/*.png (all, or the NAMEs of
#                     tests/golden/goldens.cmake), printing per image what changed:
#                     new, unchanged, or how many pixels differ and by how much
#                     (docs/testing.md: review, then commit)
#   ./setup.sh deps | build
#
# Options: --sanitize none|address|thread|undefined|fuzz  one build only (none = plain)
#          --build-dir DIR
# Anything else is passed on to the demo (demo), to ctest (test) or names the
# goldens to regenerate (golden).
set -euo pipefail
cd "$(dirname "$0")"

cmd=${1:-demo}
[ $# -gt 0 ] && shift
sanitize=""
sanitize_given=""
build_dir=""
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --sanitize) sanitize=$2; sanitize_given=1; [ "$sanitize" = none ] && sanitize=""; shift 2 ;;
    --build-dir) build_dir=$2; shift 2 ;;
    *) extra+=("$1"); shift ;;
  esac
done
dir_for() { [ -n "$build_dir" ] && echo "$build_dir" || echo "build${1:+-$1}"; }

packages=(
  cmake make gcc clang libclang-rt-14-dev pkg-config
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers
  glslang-dev spirv-tools libspirv-cross-c-shared-dev
  libcglm-dev libstb-dev zlib1g-dev libassimp-dev assimp-testmodels libcjson-dev
  libcmocka-dev gnuplot-nox libglfw3-dev xvfb xauth
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

# build SANITIZER: configure and build into its directory.
build() {
  local dir; dir=$(dir_for "$1")
  local cfg=(-S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo)
  [ -n "$1" ] && cfg+=(-DOB_SANITIZE="$1" -DCMAKE_C_COMPILER=clang)
  cmake "${cfg[@]}" >/dev/null
  cmake --build "$dir" -j"$(nproc)"
}

# suite SANITIZER: build, then run every test of that build.
suite() {
  local dir; dir=$(dir_for "$1")
  echo "== test suite: ${1:-plain} build ($dir)"
  build "$1"
  ctest --test-dir "$dir" --output-on-failure -j"$(nproc)" "${extra[@]}"
}

# fuzz: the libFuzzer targets (clang) and their bounded runs (ctest label fuzz).
fuzz() {
  local dir; dir=$([ -n "$build_dir" ] && echo "$build_dir" || echo build-fuzz)
  echo "== fuzzing: one bounded run per target ($dir)"
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
        -DOB_FUZZ=ON >/dev/null
  cmake --build "$dir" -j"$(nproc)" --target fuzz_scene_file fuzz_model
  ctest --test-dir "$dir" -L fuzz --output-on-failure -j"$(nproc)" "${extra[@]}"
}
# lavapipe and the loader warn about a missing XDG_RUNTIME_DIR on bare machines.
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}

case "$cmd" in
  deps) deps ;;
  build) deps; build "$sanitize" ;;
  demo)
    deps; build "$sanitize"
    dir=$(dir_for "$sanitize")
    "$dir"/bin/obelisk-mirror --frames 60 --out "$dir"/obelisk-mirror.png "${extra[@]}" ;;
  test)
    deps
    if [ "$sanitize" = fuzz ]; then
      fuzz
    elif [ -n "$sanitize_given" ]; then
      suite "$sanitize"
    else
      suite ""; suite address; suite thread; fuzz
    fi ;;
  golden)
    deps; build "$sanitize"
    dir=$(dir_for "$sanitize")
    cmake --build "$dir" --target ob_golden >/dev/null
    only=$(IFS=';'; echo "${extra[*]:-}")
    cmake -DBIN="$dir"/bin -DTOOL="$dir"/tests/ob_golden -DSRC="$PWD" -DOUT="$dir"/golden-update \
          -DONLY="$only" -P tests/tools/golden_update.cmake ;;
  *) echo "usage: $0 demo|test|golden|deps|build [--sanitize none|address|thread|undefined|fuzz]" >&2; exit 2 ;;
esac
