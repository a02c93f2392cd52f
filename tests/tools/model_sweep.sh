#!/bin/sh
# model_sweep.sh — obelisk-view, headless, on every glTF/OBJ/PLY model under a
# folder (default: Debian's assimp-testmodels), each under a time limit; then
# the counts: rendered, refused with a message (and the message), and
# crashed or hung, which must be zero. Not run by ctest (a few minutes on
# lavapipe); run it by hand after changing the model loader:
#
#   tests/tools/model_sweep.sh [build/bin/obelisk-view] [models folder] [seconds each]
#
# Exit status: 0 when nothing crashed, hung or printed a validation message;
# 1 otherwise. Validation is on (OB_VALIDATION=1) for every run.
view=${1:-build/bin/obelisk-view}
dir=${2:-/usr/share/assimp/models}
limit=${3:-120}
[ -x "$view" ] || { echo "model_sweep: $view is not an executable (build first)" >&2; exit 2; }
[ -d "$dir" ] || { echo "model_sweep: $dir: no such folder (install assimp-testmodels)" >&2; exit 2; }
work=$(mktemp -d /tmp/ob-model-sweep-XXXXXX)
trap 'rm -rf "$work"' EXIT

rendered=0 refused=0 broken=0 total=0
find "$dir" -type f \( -iname '*.gltf' -o -iname '*.glb' -o -iname '*.obj' -o -iname '*.ply' \) | sort > "$work/list"
while IFS= read -r model; do
    total=$((total + 1))
    OB_VALIDATION=1 timeout -k 10 "$limit" "$view" "$model" --frames 2 --quiet --size 160x120 \
        --out "$work/out.png" > "$work/stdout" 2> "$work/stderr" < /dev/null
    code=$?
    rel=${model#"$dir"/}
    validation=$(grep -E '^validation: [1-9]|validation: [0-9]+ errors, [1-9]' "$work/stdout" "$work/stderr" | head -1)
    if [ "$code" -eq 0 ] && [ -z "$validation" ] && [ -s "$work/out.png" ]; then
        rendered=$((rendered + 1))
        printf 'rendered  %s\n' "$rel"
    elif [ "$code" -eq 2 ] || { [ "$code" -eq 1 ] && [ -z "$validation" ]; }; then
        refused=$((refused + 1))
        # The loader's own reason: its first error line, else obelisk-view's.
        why=$(grep -m1 -E '\[(error|model)\]|^\[model\]|: refused:|assimp could not|contains no|not finite|out of range' "$work/stderr")
        [ -n "$why" ] || why=$(grep -m1 'obelisk-view:' "$work/stderr")
        printf 'refused   %s: %s\n' "$rel" "$(printf '%s' "$why" | sed -e "s|$dir/||g" -e 's/ ([a-z_]*\.c:[0-9]*)$//')"
    else
        broken=$((broken + 1))
        if [ "$code" -ge 124 ] && [ "$code" -le 137 ] && [ "$code" -ne 126 ]; then what="hung or killed (exit $code)"
        elif [ -n "$validation" ]; then what="validation messages: $validation"
        else what="crashed (exit $code)"; fi
        printf 'BROKEN    %s: %s\n' "$rel" "$what"
        tail -5 "$work/stderr" | sed 's/^/          /'
    fi
done < "$work/list"
printf '\n%d models: %d rendered, %d refused with a message, %d crashed, hung or not validation-clean\n' \
    "$total" "$rendered" "$refused" "$broken"
[ "$broken" -eq 0 ]
