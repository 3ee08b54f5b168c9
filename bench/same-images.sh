#!/usr/bin/env bash
# Whether two pathlight builds' CPU backends render the same images, bit for bit: the check a
# step that should change only the CPU backend's speed passes before it is timed (BENCHMARKS.md
# says "images cmp-identical on N of N" of it). Renders every reference scene of scenes/refs
# and every scene of scenes/ (or the scenes named) with both builds, small (64x64, 16 spp by
# default), one thread, at every instruction-set level this CPU runs (PATHLIGHT_CPU_LEVEL:
# baseline, x86-64-v3, x86-64-v4+gfni where present), as OpenEXR, and compares the files byte
# for byte. Prints each pair that differs and the count of each; exits 1 if any differs or a
# render fails.
#
#   bash bench/same-images.sh [--res N] [--spp N] BASE NEW [SCENE...]
#     BASE, NEW: pathlight binaries; SCENE: a name in scenes/refs or a path to a scene file
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/common.sh
RES=64 SPP=16 ARGS=()
while [ $# -gt 0 ]; do
    case "$1" in
        --res) RES=$2; shift 2 ;;
        --spp) SPP=$2; shift 2 ;;
        -*) echo "unknown option: $1" >&2; exit 2 ;;
        *) ARGS+=("$1"); shift ;;
    esac
done
if [ ${#ARGS[@]} -lt 2 ]; then
    echo "usage: bash bench/same-images.sh [--res N] [--spp N] BASE NEW [SCENE...]" >&2
    exit 2
fi
BASE=${ARGS[0]} NEW=${ARGS[1]}
require_executables "$BASE" "$NEW"
SCENES=()
add_scenes "${ARGS[@]:2}"
if [ ${#SCENES[@]} -eq 0 ]; then
    SCENES=(scenes/refs/*.toml scenes/*.toml)
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# Renders scene $2 with binary $1 at level $3 to $4; prints the log on failure.
render() {
    if ! PATHLIGHT_CPU_LEVEL=$3 RAYON_NUM_THREADS=1 "$1" render "$2" --backend cpu \
        --width "$RES" --height "$RES" --spp "$SPP" -o "$4" >"$4.log" 2>&1; then
        echo "$1 failed on $2 at $3:" >&2
        cat "$4.log" >&2
        return 1
    fi
}

# The levels this CPU runs: each one the base build does not refuse.
LEVELS=()
for level in baseline x86-64-v3 x86-64-v4+gfni; do
    if PATHLIGHT_CPU_LEVEL=$level "$BASE" render "${SCENES[0]}" --backend cpu --width 8 \
        --height 8 --spp 1 -o "$out/probe.exr" >/dev/null 2>&1; then
        LEVELS+=("$level")
    fi
done
[ ${#LEVELS[@]} -gt 0 ] || { echo "$BASE renders at no level" >&2; exit 1; }
echo "$RES x $RES, $SPP spp, levels ${LEVELS[*]}, ${#SCENES[@]} scenes"
same=0 differ=0 failed=0
for scene in "${SCENES[@]}"; do
    name=$(basename "$scene" .toml)
    for level in "${LEVELS[@]}"; do
        a=$out/$name-$level-base.exr b=$out/$name-$level-new.exr
        if ! render "$BASE" "$scene" "$level" "$a" || ! render "$NEW" "$scene" "$level" "$b"; then
            failed=$((failed + 1))
        elif cmp -s "$a" "$b"; then
            same=$((same + 1))
        else
            differ=$((differ + 1))
            echo "differs: $scene at $level"
        fi
    done
done
echo "same $same, differ $differ, failed $failed"
[ "$differ" -eq 0 ] && [ "$failed" -eq 0 ]
