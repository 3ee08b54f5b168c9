#!/usr/bin/env bash
# Times pathlight and Mitsuba 3 on the same machine, in one run: cornell-spheres at 512x512,
# 64 spp, the scene's max_depth. pathlight: whole-process time of `pathlight render` (CPU
# backend with its default Sobol sampler and with the independent sampler Mitsuba uses here,
# median of 3 each; and one run of the GPU backend on whatever adapter is found). Mitsuba:
# render time alone (llvm_ad_rgb, after one untimed render that compiles its kernels),
# median of 3. Quality: each image's relMSE against the stored converged reference
# (scenes/refs/images), the same measure as the reference tests.
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

# Whole-process wall time of a pathlight render into $out/$2.exr, in seconds: the median of
# $1 runs.
time_pathlight() {
    local runs=$1 image=$2 start end run times=()
    shift 2
    for run in $(seq "$runs"); do
        start=$(date +%s.%N)
        ./target/release/pathlight render "scenes/refs/$SCENE.toml" --width $RES --height $RES \
            --spp $SPP -o "$out/$image.exr" "$@" 2>"$out/log" || { cat "$out/log"; exit 1; }
        end=$(date +%s.%N)
        times+=("$(awk "BEGIN { print $end - $start }")")
    done
    printf '%s\n' "${times[@]}" | sort -g | sed -n "$(((runs + 1) / 2))p"
}

samples=$((RES * RES * SPP))
cpu_s=$(time_pathlight 3 sobol --backend cpu)
cpu_ind_s=$(time_pathlight 3 independent --backend cpu --sampler independent)
if [ "${1:-}" != "--skip-gpu" ]; then
    gpu_s=$(time_pathlight 1 gpu --backend gpu)
    adapter=$(grep -o 'adapter: .*' "$out/log" | head -1)
fi
mitsuba_json=$("$VENV/bin/python" tools/mitsuba_refs.py time $SCENE --res $RES --spp $SPP \
    --save "$out/mitsuba.exr")
mitsuba_s=$(echo "$mitsuba_json" | "$VENV/bin/python" -c 'import json,sys; print(json.load(sys.stdin)["median_seconds"])')
# Quality: relMSE of each image against the converged reference (its 256x256 box average).
relmse_json=$("$VENV/bin/python" tools/mitsuba_refs.py relmse-of $SCENE "$out"/*.exr)
relmse() {
    echo "$relmse_json" | "$VENV/bin/python" -c '
import json, sys
print(next(r["relmse"] for r in map(json.loads, sys.stdin) if r["image"].endswith("/" + sys.argv[1])))' "$1.exr"
}

row() { # label seconds image
    printf '%-48s %8.2f %12.2f %10.5f\n' "$1" "$2" "$(awk "BEGIN { print $samples / $2 / 1e6 }")" "$(relmse "$3")"
}
max_depth=$(sed -n 's/^max_depth *= *//p' "scenes/refs/$SCENE.toml")
printf '%-48s %8s %12s %10s\n' "$SCENE ${RES}x${RES}, $SPP spp, max_depth $max_depth" "seconds" "M samples/s" "relMSE"
row "pathlight --backend cpu, Sobol (process)" "$cpu_s" sobol
row "pathlight --backend cpu, independent (process)" "$cpu_ind_s" independent
if [ -n "${gpu_s:-}" ]; then
    row "pathlight --backend gpu, Sobol (process)" "$gpu_s" gpu
    echo "    ($adapter)"
fi
row "Mitsuba 3 llvm_ad_rgb, independent (render)" "$mitsuba_s" mitsuba
printf 'pathlight cpu / Mitsuba samples/s: %.2f (Sobol, the default), %.2f (independent, as Mitsuba)\n' \
    "$(awk "BEGIN { print $mitsuba_s / $cpu_s }")" "$(awk "BEGIN { print $mitsuba_s / $cpu_ind_s }")"
