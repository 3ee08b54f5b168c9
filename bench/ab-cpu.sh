#!/usr/bin/env bash
# Two builds of pathlight's CPU backend against each other, on this machine, in one run: the
# measure BENCHMARKS.md calls "par.". Each round renders a scene with both builds at once, one
# thread each, pinned to CPUs 0 and 1 and swapped from round to round, so that both see the
# same moment of a shared host (on these 2-core machines a build's rate moves by 10% or more
# between runs, but two builds run side by side move together). Printed per scene: the median
# of the per-round ratios NEW / BASE of the samples/s (the inverse ratio of the render times
# each `render` reports, to the millisecond; above 1: NEW is faster), then every round's ratio.
# Run against itself, a build's medians came within 1-2% of 1 (8 rounds; BENCHMARKS.md); a
# render under a second is noisier: give the furnace `--spp 512`. A change of a few percent
# needs more than one profile training of each side to be believed (BENCHMARKS.md, "A
# profile's training moves a scene by 6%"): build both in the same tree, since the tree's path
# moves the layout too.
#
# `--alone` renders the builds one after the other instead, each alone on CPU 0 (which goes first
# alternates), and prints the ratios BASE / NEW of their fastest and of their median render
# times: the fastest of many rounds is the render least disturbed by the host. On a busy
# shared host (load 1.2-1.5, 2026-11-28) side by side gave 0.92 and then 1.10 for the same two
# builds, where alone a build against itself came within 1% (15 rounds at 128x128).
#
# `--count` adds the instructions each build runs for the render alone (valgrind's
# cachegrind, one thread, 64x64: the count at 24 spp less the count at 8 spp, so that loading
# and writing cancel; within 1.5% from run to run, and hardly moved by a training, but not a
# measure of time). Valgrind runs the x86-64-v3 row renderer whatever the CPU has. Installs
# valgrind (apt-get, as root or with sudo) where it is missing.
#
#   bash bench/ab-cpu.sh [--rounds N] [--spp N] [--res N] [--alone] [--count] BASE NEW [SCENE...]
#     BASE, NEW: pathlight binaries; SCENE: a name in scenes/refs or a path to a scene file
#     defaults: 8 rounds, 128 spp, 256x256, every scene of scenes/refs (the furnace rings
#     left out but furnace-0.8)
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/common.sh
ROUNDS=8 SPP=128 RES=256 ALONE=false COUNT=false ARGS=()
while [ $# -gt 0 ]; do
    case "$1" in
        --rounds) ROUNDS=$2; shift 2 ;;
        --spp) SPP=$2; shift 2 ;;
        --res) RES=$2; shift 2 ;;
        --alone) ALONE=true; shift ;;
        --count) COUNT=true; shift ;;
        -*) echo "unknown option: $1" >&2; exit 2 ;;
        *) ARGS+=("$1"); shift ;;
    esac
done
if [ ${#ARGS[@]} -lt 2 ]; then
    echo "usage: bash bench/ab-cpu.sh [--rounds N] [--spp N] [--res N] [--alone] [--count] BASE NEW [SCENE...]" >&2
    exit 2
fi
BASE=${ARGS[0]} NEW=${ARGS[1]}
require_executables "$BASE" "$NEW"
if [ "$(nproc)" -lt 2 ]; then
    echo "needs two CPUs (this machine has $(nproc)): the builds run side by side" >&2
    exit 1
fi
SCENES=()
add_scenes "${ARGS[@]:2}"
if [ ${#SCENES[@]} -eq 0 ]; then
    for f in scenes/refs/*.toml; do
        name=$(basename "$f" .toml)
        case "$name" in furnace-*) [ "$name" = furnace-0.8 ] || continue ;; esac
        SCENES+=("$f")
    done
fi
if $COUNT && ! command -v valgrind >/dev/null; then
    sudo_if_needed() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }
    sudo_if_needed apt-get update
    sudo_if_needed apt-get install -y valgrind
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# Renders scene $2 with binary $1 on CPU $3 into $4 (a log), in the background.
render_on() {
    RAYON_NUM_THREADS=1 taskset -c "$3" "$1" render "$2" --backend cpu --width "$RES" \
        --height "$RES" --spp "$SPP" -o "$out/$(basename "$4" .log).exr" >"$4" 2>&1 &
}
# The render time (seconds) a render's log reports.
seconds() {
    local t
    t=$(sed -n 's/.*render \([0-9.]*\) s (.*/\1/p' "$1")
    [ -n "$t" ] || { echo "a render failed:" >&2; cat "$1" >&2; exit 1; }
    echo "$t"
}
# Instructions (millions) binary $1 runs to render scene $2 at 64x64, 24 spp less 8 spp.
instructions() {
    local counts=()
    for spp in 8 24; do
        counts+=("$(RAYON_NUM_THREADS=1 valgrind --tool=cachegrind --cache-sim=no \
            --cachegrind-out-file=/dev/null "$1" render "$2" --backend cpu --width 64 \
            --height 64 --spp "$spp" -o "$out/count.exr" 2>&1 |
            sed -n 's/.*I *refs: *\([0-9,]*\).*/\1/p' | tr -d ,)")
    done
    echo $(((counts[1] - counts[0]) / 1000000))
}

echo "$(date -u +%F), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) CPUs, load $(cut -d' ' -f1 /proc/loadavg)"
if $ALONE; then
    echo "BASE $BASE, NEW $NEW: ${RES}x${RES}, $SPP spp, $ROUNDS rounds, each alone on CPU 0, one thread"
else
    echo "BASE $BASE, NEW $NEW: ${RES}x${RES}, $SPP spp, $ROUNDS rounds, both at once, one thread each"
fi
# The median of the numbers on standard input.
median() {
    sort -g | awk '{ v[NR] = $1 } END { print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }'
}
for scene in "${SCENES[@]}"; do
    ratios=() base_times=() new_times=()
    for round in $(seq "$ROUNDS"); do
        if $ALONE; then
            for who in $(if [ $((round % 2)) = 1 ]; then echo base new; else echo new base; fi); do
                if [ "$who" = base ]; then bin=$BASE; else bin=$NEW; fi
                render_on "$bin" "$scene" 0 "$out/$who.log"
                wait
            done
            base_times+=("$(seconds "$out/base.log")")
            new_times+=("$(seconds "$out/new.log")")
            continue
        fi
        cpu_base=$((round % 2)) cpu_new=$(((round + 1) % 2))
        render_on "$BASE" "$scene" "$cpu_base" "$out/base.log"
        render_on "$NEW" "$scene" "$cpu_new" "$out/new.log"
        wait
        ratios+=("$(awk -v b="$(seconds "$out/base.log")" -v n="$(seconds "$out/new.log")" \
            'BEGIN { printf "%.3f", b / n }')")
    done
    if $ALONE; then
        fastest() { printf '%s\n' "$@" | sort -g | head -1; }
        base_min=$(fastest "${base_times[@]}") new_min=$(fastest "${new_times[@]}")
        base_median=$(printf '%s\n' "${base_times[@]}" | median)
        new_median=$(printf '%s\n' "${new_times[@]}" | median)
        line="$(basename "$scene" .toml): NEW/BASE fastest $(awk -v b="$base_min" -v n="$new_min" \
            'BEGIN { printf "%.3f", b / n }') ($base_min s, $new_min s), median $(awk \
            -v b="$base_median" -v n="$new_median" 'BEGIN { printf "%.3f", b / n }') ($base_median s, $new_median s)"
    else
        line="$(basename "$scene" .toml): NEW/BASE median $(printf '%s\n' "${ratios[@]}" | median), rounds ${ratios[*]}"
    fi
    if $COUNT; then
        base_count=$(instructions "$BASE" "$scene")
        new_count=$(instructions "$NEW" "$scene")
        line+="; instructions $base_count -> $new_count M"
    fi
    echo "$line"
done
