#!/usr/bin/env bash
# Obelisk set-up, build and run. One entry point for the README and CI.
#
#   ./setup.sh demo   install missing packages, build, render the main demo headless
#   ./setup.sh test   install missing packages, then build and run the whole test
#                     suite three times: plain (build/), address+undefined
#                     sanitizers (build-address/) and thread sanitizer (build-thread/),
#                     then the fuzz targets replay every saved input once (build-fuzz/;
#                     deterministic: no random search decides whether a commit lands)
#                     The plain suite also installs the build into
#                     build/package/prefix and builds and runs examples/ against
#                     it, out of tree (ctest label package, tests/package/)
#   ./setup.sh golden [NAME...]  install missing packages, build, and regenerate
#                     the golden images tests/golden/*.png (all, or the NAMEs of
#                     tests/golden/goldens.cmake), printing per image what changed:
#                     new, unchanged, or how many pixels differ and by how much
#                     (docs/testing.md: review, then commit)
#   ./setup.sh fuzz-explore [SECONDS]  exploratory fuzzing, outside CI: SECONDS (default
#                     600) of libFuzzer on each target from the saved corpus, then a
#                     triage; fix what it finds in our code and save the input in
#                     fuzz/corpus/scene or fuzz/corpus/model-findings (docs/testing.md)
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

# fuzz: the libFuzzer targets (clang) and the replay of every saved input
# (ctest label fuzz): what CI runs.
fuzz_build() {
  cmake -S . -B "$1" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
        -DOB_FUZZ=ON >/dev/null
  cmake --build "$1" -j"$(nproc)" --target fuzz_scene_file fuzz_model
}
fuzz() {
  local dir; dir=$([ -n "$build_dir" ] && echo "$build_dir" || echo build-fuzz)
  echo "== fuzzing: replaying every saved input ($dir)"
  fuzz_build "$dir"
  ctest --test-dir "$dir" -L fuzz --output-on-failure -j"$(nproc)" "${extra[@]}"
}
# fuzz-explore [SECONDS]: random search from the saved corpus, by hand. New
# inputs go to $dir/fuzz/explore-*, findings to $dir/fuzz/artifacts-*.
fuzz_explore() {
  local dir; dir=$([ -n "$build_dir" ] && echo "$build_dir" || echo build-fuzz)
  local seconds=${extra[0]:-600}
  fuzz_build "$dir"
  mkdir -p "$dir/fuzz/explore-scene" "$dir/fuzz/artifacts-scene"
  echo "== exploring fuzz_scene_file for ${seconds} s"
  "$dir"/bin/fuzz_scene_file -dict=fuzz/scene_file.dict -max_total_time="$seconds" -timeout=10 \
      -rss_limit_mb=2048 -artifact_prefix="$dir/fuzz/artifacts-scene/" \
      "$dir/fuzz/explore-scene" fuzz/corpus/scene
  echo "== exploring fuzz_model for ${seconds} s"
  cmake -DMODE=explore -DFUZZER="$dir"/bin/fuzz_model -DWORK="$dir/fuzz/explore-model" \
        "-DSEEDS=fuzz/corpus/model;fuzz/corpus/model-findings" \
        -DARTIFACTS="$dir/fuzz/artifacts-model" -DSECONDS="$seconds" -P fuzz/model_run.cmake
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
  fuzz-explore) deps; fuzz_explore ;;
  golden)
    deps; build "$sanitize"
    dir=$(dir_for "$sanitize")
    cmake --build "$dir" --target ob_golden >/dev/null
    only=$(IFS=';'; echo "${extra[*]:-}")
    cmake -DBIN="$dir"/bin -DTOOL="$dir"/tests/ob_golden -DSRC="$PWD" -DOUT="$dir"/golden-update \
          -DONLY="$only" -P tests/tools/golden_update.cmake ;;
  *) echo "usage: $0 demo|test|golden|fuzz-explore|deps|build [--sanitize none|address|thread|undefined|fuzz]" >&2; exit 2 ;;
esac
