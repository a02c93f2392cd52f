#!/usr/bin/env bash
# gpu_pack.sh — bundle this checkout's plain build (build/) for a machine with
# a real GPU that has only a driver: no compiler, no CMake, no Vulkan SDK, no
# network. Writes .gpu/ob.tar.xz (git-ignored through .git/info/exclude) and
# copies tests/tools/gpu_run.sh beside it; bring .gpu/ there and run
# `bash .gpu/gpu_run.sh` in the checkout's root (docs/testing.md, "Running the
# suite on a real GPU").
#
# The bundle holds: the source of HEAD (shaders, scenes, golden images, ctest
# scripts); build/ without objects, stripped, with only the test executables
# named in KEEP (each is ~9 MB: glslang is static); every shared library they
# need except glibc's; Debian's Vulkan loader, glvnd and validation layer;
# cmake and ctest with CMake's modules (ctest runs the goldens and demo tests
# through `cmake -P`, and the test files name cmake by its absolute path
# here); and the assimp test models the tests read.
#
# Usage: tests/tools/gpu_pack.sh        (after ./setup.sh build, or cmake --build build)
#   KEEP="test_a test_b"  the test executables to carry (default: every one
#                         that a test ctest labels gpu runs; xz keeps the copies of the
#                         static glslang in them to ~0.4 MB each)
#   DEST=DIR              where to write (default .gpu)
set -euo pipefail
PROJ=${PROJ:-$(git -C "$(dirname "$0")" rev-parse --show-toplevel)}
DEST=${DEST:-$PROJ/.gpu}
[ -x "$PROJ/build/bin/obelisk-view" ] || { echo "gpu_pack: build first (no $PROJ/build/bin/obelisk-view)" >&2; exit 2; }
# The executables, not the test names: one executable may run as several
# tests (test_faults as test_faults_start, _first, ...), which a list of names
# left behind (the H200 run of 2026-11-28: six fault groups "Not Run").
KEEP=${KEEP:-$(ctest --test-dir "$PROJ/build" -N -L gpu --show-only=json-v1 | python3 -c '
import json, os, sys
names = {os.path.basename(t["command"][0]) for t in json.load(sys.stdin)["tests"] if t.get("command")}
print(" ".join(sorted(n for n in names if n.startswith("test_"))))')}
[ -n "${KEEP// /}" ] || { echo "gpu_pack: ctest lists no gpu tests in $PROJ/build" >&2; exit 2; }

stage=$(mktemp -d); trap 'rm -rf "$stage"' EXIT
root=$stage/ob; mkdir -p "$root/main" "$root/libs" "$root/layers" "$root/models" "$root/cmake/bin" "$root/cmake/share"
echo "$PROJ" > "$root/PROJ_PATH"   # ctest files hold absolute paths: gpu_run.sh recreates this one
git -C "$PROJ" rev-parse --short HEAD > "$root/COMMIT"
git -C "$PROJ" archive HEAD | tar -x -C "$root/main"
(cd "$PROJ" && find build \( -type f -o -type l \) ! -name '*.o' ! -name '*.a' ! -path '*/CMakeFiles/*' \
    ! -name '*.d' ! -path 'build/package/*' ! -path 'build/golden-out/*' ! -path 'build/demo-out/*' \
    ! -path 'build/soak/*' ! -path 'build/test-cache/*' -print0 | tar --null -T - -c) | tar -x -C "$root/main"
for f in "$root"/main/build/tests/test_*; do
  case " $KEEP " in *" $(basename "$f") "*) ;; *) rm -f "$f" ;; esac
done
find "$root/main/build" -type f -perm -u+x -exec sh -c 'file -b "$1" | grep -q ELF && strip "$1"' _ {} \;

# cmake and ctest, with CMake's modules at the place cmake looks for them
# (../share/cmake-X.Y beside its binary).
cp -L "$(command -v cmake)" "$(command -v ctest)" "$root/cmake/bin/"
cmroot=$(cmake --system-information 2>/dev/null | sed -n 's/^CMAKE_ROOT "\(.*\)"$/\1/p' | head -1)
[ -d "$cmroot" ] || cmroot=$(ls -d /usr/share/cmake-3.* | head -1)
cp -a "$cmroot" "$root/cmake/share/"

# Shared libraries of everything carried, glibc's excepted.
{ find "$root/main/build" -type f -perm -u+x; echo "$root/cmake/bin/cmake"; echo "$root/cmake/bin/ctest"; } |
  while read -r f; do file -b "$f" | grep -q ELF && ldd "$f"; done 2>/dev/null |
  awk '/=> \//{print $3}' | sort -u | grep -vE '/(libc|libm|libdl|libpthread|librt|ld-linux[^/]*)\.so' |
  while read -r l; do cp -L "$l" "$root/libs/"; done
cp -L /usr/lib/x86_64-linux-gnu/libvulkan.so.1 /usr/lib/x86_64-linux-gnu/libVkLayer_khronos_validation.so "$root/libs/"
cp /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json "$root/layers/"
# glvnd: the NVIDIA Vulkan driver loads libGLX/libEGL through it.
gl=$(mktemp -d)
(cd "$gl" && apt-get download -q libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 >/dev/null 2>&1) || true
for d in "$gl"/*.deb; do [ -f "$d" ] && dpkg -x "$d" "$gl/x"; done
cp -a "$gl"/x/usr/lib/x86_64-linux-gnu/*.so* "$root/libs/" 2>/dev/null ||
  echo "gpu_pack: no glvnd libraries packed (apt-get update first?); the NVIDIA driver may not load" >&2
rm -rf "$gl"
for d in glTF2 OBJ PLY; do
  [ -d "/usr/share/assimp/models/$d" ] && cp -a "/usr/share/assimp/models/$d" "$root/models/"
done

mkdir -p "$DEST"
tar -C "$stage" -cf - ob | xz -T2 -9 > "$DEST/ob.tar.xz"
cp "$(dirname "$0")/gpu_run.sh" "$DEST/"
exclude=$(git -C "$PROJ" rev-parse --git-path info/exclude)
case $exclude in /*) ;; *) exclude=$PROJ/$exclude ;; esac
mkdir -p "$(dirname "$exclude")"
grep -qx "/.gpu/" "$exclude" 2>/dev/null || echo "/.gpu/" >> "$exclude"
ls -la "$DEST"
