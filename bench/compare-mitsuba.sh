#!/usr/bin/env bash
# Times pathlight and Mitsuba 3 on the same machine, in one run: cornell-spheres at 512x512,
# 64 spp, the scene's max_depth. pathlight: whole-process time of `pathlight render` (CPU
# backend, and the GPU backend on whatever adapter is found). Mitsuba: render time alone
# (llvm_ad_rgb, after one untimed render that compiles its kernels), median of 3.
#
# Installs what it needs: Debian's libllvm19 and python3-venv (apt-get, as root or with
# sudo), then Mitsuba and NumPy from pip into a virtual environment (MITSUBA_VENV, default
# bench/.venv). Usage: bash bench/compare-mitsuba.sh [--skip-gpu]
set -euo pipefail
cd "$(dirname "$0")/.."
SCENE=cornell-spheres RES=512 SPP=64
VENV=${MITSUBA_VENV:-bench/.venv}
LLVM=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1

sudo_if_needed() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }
if [ ! -e "$LLVM" ] || ! python3 -c 'import venv, ensurepip' 2>/dev/null; then
    sudo_if_needed apt-get update
    sudo_if_needed apt-get install -y libllvm19 python3-venv
fi
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install --quiet mitsuba numpy
fi
export DRJIT_LIBLLVM_PATH=$LLVM

cargo build --release --locked --quiet
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "load: $(cut -d' ' -f1-3 /proc/loadavg) (a busy machine halves both sides)"

# Whole-process wall time of one pathlight render, in seconds.
time_pathlight() {
    local start end
    start=$(date +%s.%N)
    ./target/release/pathlight render "scenes/refs/$SCENE.toml" --width $RES --height $RES \
        --spp $SPP -o "$out/pathlight.exr" "$@" 2>"$out/log" || { cat "$out/log"; exit 1; }
    end=$(date +%s.%N)
    awk "BEGIN { print $end - $start }"
}

samples=$((RES * RES * SPP))
cpu_s=$(time_pathlight --backend cpu)
mitsuba_json=$("$VENV/bin/python" tools/mitsuba_refs.py time $SCENE --res $RES --spp $SPP)
mitsuba_s=$(echo "$mitsuba_json" | "$VENV/bin/python" -c 'import json,sys; print(json.load(sys.stdin)["median_seconds"])')

printf '%-34s %10s %14s\n' "$SCENE ${RES}x${RES}, $SPP spp" "seconds" "M samples/s"
printf '%-34s %10.2f %14.2f\n' "pathlight --backend cpu (process)" "$cpu_s" "$(awk "BEGIN { print $samples / $cpu_s / 1e6 }")"
if [ "${1:-}" != "--skip-gpu" ]; then
    gpu_s=$(time_pathlight --backend gpu)
    adapter=$(grep -o 'adapter: .*' "$out/log" | head -1)
    printf '%-34s %10.2f %14.2f   (%s)\n' "pathlight --backend gpu (process)" "$gpu_s" "$(awk "BEGIN { print $samples / $gpu_s / 1e6 }")" "$adapter"
fi
printf '%-34s %10.2f %14.2f\n' "Mitsuba 3 llvm_ad_rgb (render)" "$mitsuba_s" "$(awk "BEGIN { print $samples / $mitsuba_s / 1e6 }")"
printf 'pathlight cpu / Mitsuba samples/s: %.2f\n' "$(awk "BEGIN { print $mitsuba_s / $cpu_s }")"
