#!/bin/sh
# soak.sh — long run of obelisk-mirror switching single/multi-threaded
# recording every frame, under the validation layer, watching its memory.
#
# Checks (exit 1 if any fails, details on stdout and in OUT/report.txt):
#   - resident memory grows by less than 1% after the warm-up: the process's
#     VmRSS after every frame (obelisk-mirror --stats-json, "rss_kb") is
#     compared between the end of the warm-up and the end of the run, as the
#     medians of the first and the last tenth of the frames after the warm-up
#     (RSS moves by a few MB from frame to frame as the driver allocates and
#     frees its per-frame memory). The live C heap ("heap_in_use_kb",
#     glibc's mallinfo2) is reported the same way, to tell memory the program
#     holds from pages the allocator keeps;
#   - the run exits 0: obelisk-mirror exits 3 if the validation layer (with
#     synchronization validation) said anything; its counts are reported;
#   - the final image is byte-identical (same pixels; PNG encoding is
#     deterministic) to a run of the same frames that never switched
#     (--threads 0, without the validation layer, which does not change
#     pixels).
#
# Usage: tests/soak/soak.sh [--frames N] [--objects N] [--build DIR] [--out DIR]
#                           [--warmup-frames N] [--malloc-threshold KIB]
#                           [--no-reference] [--parallel] [-- MIRROR-ARGS...]
# Defaults: 10000 frames, 2000 objects, build dir ./build, out dir
# ./build/soak, warm-up = the first 10% of the frames. MIRROR-ARGS go to both
# runs (e.g. --size 320x240). --parallel runs the reference at the same time
# as the soak instead of after it (same results, less wall time when the
# machine has cores to spare). --malloc-threshold goes to the soak run
# (default 128: glibc's mmap and trim thresholds fixed at 128 KiB; 0 leaves
# glibc's dynamic policy, under which RSS rises in steps for thousands of
# frames as arenas keep freed driver blocks; see docs/soak.md).
# LP_NUM_THREADS defaults to 0 for both runs (lavapipe; why below). See
# docs/soak.md for measured results and times.
set -eu

frames=10000
objects=2000
build=build
out=
warmup_frames=
reference=1
parallel=0
malloc_threshold=128

while [ $# -gt 0 ]; do
    case "$1" in
    --frames) frames=$2; shift 2 ;;
    --objects) objects=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --warmup-frames) warmup_frames=$2; shift 2 ;;
    --malloc-threshold) malloc_threshold=$2; shift 2 ;;
    --no-reference) reference=0; shift ;;
    --parallel) parallel=1; shift ;;
    --) shift; break ;;
    -h|--help) sed -n '2,33p' "$0"; exit 0 ;;
    *) echo "soak.sh: unknown argument '$1'" >&2; exit 2 ;;
    esac
done
[ -n "$out" ] || out=$build/soak
[ -n "$warmup_frames" ] || warmup_frames=$((frames / 10))
mirror=$build/bin/obelisk-mirror
if [ ! -x "$mirror" ]; then
    echo "soak.sh: $mirror not found: build first (cmake --build $build)" >&2
    exit 2
fi
mkdir -p "$out"
: "${XDG_RUNTIME_DIR:=/tmp}"
export XDG_RUNTIME_DIR
# lavapipe only (a GPU driver ignores it): llvmpipe rasterizes on the queue
# thread instead of queueing binned scenes for its rasterizer threads. How far
# the queue runs ahead depends on scheduling and swings the live heap by
# 150 MB from frame to frame, which drowns a 1% memory check (docs/soak.md);
# set LP_NUM_THREADS to measure the default driver anyway.
: "${LP_NUM_THREADS=0}"
export LP_NUM_THREADS

# median: of the numbers on stdin, one per line.
median() { sort -n | awk '{ v[NR] = $1 } END { if (NR) print v[int((NR + 1) / 2)]; else print 0 }'; }
# field NAME: "frame value" per line from the soak's per-frame JSON.
field() {
    sed -n "s/.*\"frame\":\([0-9]*\),.*\"$1\":\([0-9]*\).*/\1 \2/p" "$out/soak.json"
}
# growth NAME: sets start, end, lo, hi and pct for that field after the warm-up.
growth() {
    field "$1" | awk -v w="$warmup_frames" '$1 > w { print $2 }' > "$out/$1.after-warmup"
    n=$(wc -l < "$out/$1.after-warmup")
    k=$((n / 10)); [ "$k" -ge 1 ] || k=1
    start=$(head -n "$k" "$out/$1.after-warmup" | median)
    end=$(tail -n "$k" "$out/$1.after-warmup" | median)
    lo=$(sort -n "$out/$1.after-warmup" | head -n 1)
    hi=$(sort -n "$out/$1.after-warmup" | tail -n 1)
    pct=$(awk -v a="$start" -v b="$end" 'BEGIN { if (a > 0) printf "%.3f", (b - a) * 100.0 / a; else print "nan" }')
}

# The reference: the same frames single-threaded, never switching.
run_reference() {
    t0_ref=$(date +%s)
    ref_rc=0
    "$mirror" --objects "$objects" --frames "$frames" --threads 0 --quiet \
        --out "$out/reference.png" "$@" > "$out/reference.log" 2>&1 || ref_rc=$?
    echo "$ref_rc $(( $(date +%s) - t0_ref ))" > "$out/reference.status"
}
rm -f "$out/reference.status" "$out/reference.png"
if [ "$reference" -eq 1 ] && [ "$parallel" -eq 1 ]; then
    echo "reference: the same $frames frames single-threaded, never switching (in parallel)"
    run_reference "$@" &
    ref_pid=$!
fi

echo "soak: $frames frames, $objects objects, toggling ST/MT every frame (2 workers), validation on"
t0=$(date +%s)
rc=0
policy=
[ "$malloc_threshold" = 0 ] || policy="--malloc-threshold $malloc_threshold"
# $policy is unquoted on purpose: empty, or an option and its value.
# shellcheck disable=SC2086
OB_VALIDATION=1 "$mirror" --objects "$objects" --frames "$frames" --toggle 1 --threads 2 --quiet \
    --out "$out/soak.png" --stats-json "$out/soak.json" $policy "$@" > "$out/soak.log" 2>&1 || rc=$?
soak_s=$(( $(date +%s) - t0 ))
errors=$(sed -n 's/^validation: \([0-9]*\) errors, \([0-9]*\) warnings$/\1/p' "$out/soak.log")
warnings=$(sed -n 's/^validation: \([0-9]*\) errors, \([0-9]*\) warnings$/\2/p' "$out/soak.log")

status=0
{
    echo "soak run: obelisk-mirror --objects $objects --frames $frames --toggle 1 --threads 2 $policy $*" \
         "(LP_NUM_THREADS=$LP_NUM_THREADS)"
    echo "  exit $rc after $soak_s s; validation: ${errors:-?} errors, ${warnings:-?} warnings"
} | tee "$out/report.txt"
if [ "$rc" -ne 0 ]; then
    echo "FAIL: obelisk-mirror exited $rc (3 = the validation layer spoke); see $out/soak.log" | tee -a "$out/report.txt"
    status=1
fi
growth heap_in_use_kb
echo "  live heap after the warm-up ($warmup_frames frames): $start kB -> $end kB at the end" \
     "(medians of $k frames; range $lo..$hi): ${pct}%" | tee -a "$out/report.txt"
growth rss_kb
echo "  VmRSS after the warm-up ($warmup_frames frames): $start kB -> $end kB at the end" \
     "(medians of $k frames; range $lo..$hi): ${pct}% (limit 1%)" | tee -a "$out/report.txt"
if ! awk -v g="$pct" 'BEGIN { exit !(g == g + 0 && g < 1.0) }'; then
    echo "FAIL: resident memory grew by ${pct}% after the warm-up" | tee -a "$out/report.txt"
    status=1
fi
# The set-0 descriptor sets a pipeline manager keeps cached between frames
# ("descriptor_sets_held", the largest of any manager): bounded at 1024 per
# frame slot whatever programs come and go (issue 25.9).
growth descriptor_sets_held
echo "  set-0 descriptor sets held after the warm-up: $start -> $end (range $lo..$hi; bound 1024)" \
    | tee -a "$out/report.txt"
if [ "${hi:-0}" -gt 1024 ]; then
    echo "FAIL: a pipeline manager held $hi set-0 descriptor sets" | tee -a "$out/report.txt"
    status=1
fi

if [ "$reference" -eq 1 ]; then
    if [ "$parallel" -eq 1 ]; then
        wait "$ref_pid" || true
    else
        echo "reference: the same $frames frames single-threaded, never switching"
        run_reference "$@"
    fi
    read -r rc ref_s < "$out/reference.status"
    echo "reference run: obelisk-mirror --objects $objects --frames $frames --threads 0 $*" | tee -a "$out/report.txt"
    echo "  exit $rc after $ref_s s" | tee -a "$out/report.txt"
    if [ "$rc" -ne 0 ]; then
        echo "FAIL: the reference run exited $rc; see $out/reference.log" | tee -a "$out/report.txt"
        status=1
    elif cmp -s "$out/soak.png" "$out/reference.png"; then
        echo "  final images identical ($out/soak.png = $out/reference.png)" | tee -a "$out/report.txt"
    else
        echo "FAIL: the final image differs from the never-switching run's" | tee -a "$out/report.txt"
        status=1
    fi
fi
[ "$status" -eq 0 ] && echo "soak: PASS" | tee -a "$out/report.txt"
exit "$status"
