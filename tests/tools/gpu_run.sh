#!/usr/bin/env bash
# gpu_run.sh [STEPS] — on the GPU machine, unpack .gpu/ob.tar.xz (made by
# tests/tools/gpu_pack.sh), recreate the build's absolute paths (the
# checkout's path, /usr/share/assimp/models, cmake where the test files name
# it), point the Vulkan loader at the NVIDIA driver and the packed validation
# layer, and run the checks, each bounded in time. Logs and results go to
# $OUT (default /tmp/out) as results.tgz, with a one-line-per-step summary.txt
# beside it.
#
# STEPS, any of (default: info suite):
#   info   obelisk-mirror 30 frames with validation: the device, and whether the
#          engine runs at all (stops the run if not)
#   suite  ctest -L 'gpu|golden|demo' on the packed tests: the labels that must
#          pass on a real GPU (docs/testing.md)
#   scale  test_extreme_scale alone (the scale invariance cases)
#   images BoxTextured and 2CylinderEngine at 640x480, 4x MSAA, into $OUT
#   bench  obelisk-bench --quick (frame periods on the GPU)
#   frame16  16 views x 100k objects, ST against 2..16 workers and auto (each
#          mode's CPU phases and ST's over them in the summary), instancing
#          on (runs as the device's default: multi-draw indirect on a GPU), then
#          runs as instanced draws (OB_INSTANCE_RUNS=instanced), as a direct
#          draw per instance (OB_INSTANCE_RUNS=direct), then one draw
#          per entity (--no-instancing), then levels of detail off (--no-lod):
#          the parallel frame's, instancing's and the levels' figures on the
#          machine's cores (docs/benchmark.md)
#   custom sources .gpu/custom.sh (put there by hand) with this environment
# DEADLINE (seconds, default 420) bounds the whole run; a step gets what is
# left or is skipped. OB_DEVICE defaults to gpu (never lavapipe).
set -u
here=$(cd "$(dirname "$0")" && pwd)
RET=${OUT:-/tmp/out}; OUT=/tmp/gpu-results; mkdir -p "$OUT" "$RET"
trap 'cp "$OUT/summary.txt" "$RET/" 2>/dev/null; tar -C "$OUT" -czf "$RET/results.tgz" .' EXIT
steps=${*:-info suite}
DEADLINE=${DEADLINE:-420}
t0=$(date +%s)
left() { echo $(( DEADLINE - ($(date +%s) - t0) )); }
say() { echo "[$(( $(date +%s) - t0 ))s] $*" | tee -a "$OUT/summary.txt"; }

mkdir -p /opt && tar -xJf "$here/ob.tar.xz" -C /opt || { echo "gpu_run: unpack failed"; exit 1; }
P=$(cat /opt/ob/PROJ_PATH); mkdir -p "$(dirname "$P")" /usr/share/assimp
# The checkout may already be at that path (without its ignored build/).
if [ -e "$P" ] && [ ! -L "$P" ]; then [ -d "$P/build" ] || cp -a /opt/ob/main/build "$P/build"
else ln -sfn /opt/ob/main "$P"; fi
[ -e /usr/share/assimp/models ] || ln -s /opt/ob/models /usr/share/assimp/models
export LD_LIBRARY_PATH=/opt/ob/libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH} VK_LAYER_PATH=/opt/ob/layers
for f in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /usr/share/vulkan/icd.d/nvidia_icd.json \
         /etc/vulkan/icd.d/nvidia_icd.json; do
  [ -f "$f" ] && { export VK_DRIVER_FILES=$f; break; }
done
[ -f /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json ] &&
  export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export OB_DEVICE=${OB_DEVICE:-gpu} XDG_RUNTIME_DIR=/tmp
export OB_SHADER_DIR=${OB_SHADER_DIR:-$P/materials/shaders}
# ctest's files name cmake by the path it had on the build machine; use the
# machine's own cmake if it has one, else the packed one.
CM=$(grep -ho 'COMMAND "[^"]*cmake"' "$P"/build/tests/CTestTestfile.cmake 2>/dev/null | head -1 | sed 's/COMMAND "\(.*\)"/\1/')
CM=${CM:-/usr/bin/cmake}
mine=$(command -v cmake || echo /opt/ob/cmake/bin/cmake)
[ -x "$CM" ] || { mkdir -p "$(dirname "$CM")"; ln -sf "$mine" "$CM"; }
CTEST=$(command -v ctest || echo /opt/ob/cmake/bin/ctest)
B=$P/build/bin
say "commit $(cat /opt/ob/COMMIT) icd=${VK_DRIVER_FILES:-none} cores=$(nproc) cmake=$CM"
nvidia-smi -L 2>&1 | head -2 | tee -a "$OUT/summary.txt"

for s in $steps; do
  [ "$(left)" -gt 20 ] || { say "skip $s: out of time"; continue; }
  case $s in
  info)
    OB_VALIDATION=1 OB_LOG=info timeout 60 "$B/obelisk-mirror" --frames 30 --out "$OUT/mirror_gpu.png" \
      >"$OUT/info.log" 2>&1
    rc=$?
    say "info rc=$rc: $(grep -m1 -oE "using #[0-9]+ '[^']*' \([^)]*\)" "$OUT/info.log")"
    [ $rc -eq 0 ] || { tail -5 "$OUT/info.log"; say "the demo does not run on this GPU: stopping"; exit 3; } ;;
  suite)
    (cd "$P/build" && timeout $(( $(left) - 5 )) "$CTEST" -L 'gpu|golden|demo' -j"$(nproc)" --timeout 300 \
      --output-on-failure) >"$OUT/suite.log" 2>&1
    say "suite rc=$?: $(grep -E 'tests passed' "$OUT/suite.log")"
    grep -E '\*\*\*Failed|Timeout|Not Run' "$OUT/suite.log" | head -20 | tee -a "$OUT/summary.txt"
    grep -h 'up to .* pixels may differ' "$OUT/suite.log" | head -5 >>"$OUT/summary.txt"
    mkdir -p "$OUT/diff"; find "$P/build" -name '*.diff.png' | head -8 | xargs -r cp -t "$OUT/diff/" ;;
  scale)
    (cd "$P/build" && OB_VALIDATION=1 timeout 120 tests/test_extreme_scale) >"$OUT/scale.log" 2>&1
    say "scale rc=$?" ;;
  images)
    for m in glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb glTF2/BoxTextured-glTF-Binary/BoxTextured.glb; do
      n=$(basename "${m%.*}")
      timeout 60 "$B/obelisk-view" "/usr/share/assimp/models/$m" --frames 2 --msaa 4 --out "$OUT/$n.png" \
        >"$OUT/view_$n.log" 2>&1
      say "image $n rc=$?"
    done ;;
  bench)
    timeout $(( $(left) * 6 / 10 )) "$B/obelisk-bench" --quick --no-stability --no-progress \
      --json "$OUT/bench_quick.json" >"$OUT/bench_quick.log" 2>&1
    say "bench rc=$?" ;;
  frame16)
    for v in inst:"--modes ST,2,4,8,16,auto" hwinst:"--modes ST,16" direct:"--modes ST,16" \
             draw:"--modes ST,16 --no-instancing" nolod:"--modes ST,16 --no-lod"; do
      n=${v%%:*}; a=${v#*:}
      # hwinst, direct: runs as instanced draws, as a direct draw per instance
      # (a GPU's default is multi-draw indirect)
      runs=; [ "$n" = hwinst ] && runs=instanced; [ "$n" = direct ] && runs=direct
      # shellcheck disable=SC2086  # $a is a list of options
      OB_INSTANCE_RUNS=$runs timeout $(( $(left) * 6 / 10 )) "$B/obelisk-bench" --views 16 --objects 100000 $a --rounds 3 \
        --no-stability --no-progress --json "$OUT/frame16_$n.json" >"$OUT/frame16_$n.log" 2>&1
      say "frame16 $n rc=$?"
      grep -E '^ +16 +100000 ' "$OUT/frame16_$n.log" | tee -a "$OUT/summary.txt"
      # The CPU phases (update + pre-render + record + assemble + submit) of
      # each mode and ST's over them, from the medians (the JSON has the
      # per-round figure, frame_cpu_speedup; no python here).
      grep -E '^ +16 +100000 ' "$OUT/frame16_$n.log" |
        awk '{c = $6 + $7 + $8 + $9 + $10; if ($3 == "ST") st = c;
              printf "       %-5s cpu phases %.2f ms, ST / this %.2f\n", $3, c, st ? st / c : 0}' |
        tee -a "$OUT/summary.txt"
    done ;;
  custom)
    # .gpu/custom.sh, if the pack has one: a prepared measurement with this
    # environment ($B, $OUT, left, say) that the steps above do not cover.
    if [ -f "$here/custom.sh" ]; then
      # shellcheck disable=SC1091
      . "$here/custom.sh"
      say "custom rc=$?"
    else say "custom: no $here/custom.sh"; fi ;;
  *) say "unknown step '$s'" ;;
  esac
done
say done
