#!/usr/bin/env bash
# pathlight's CPU backend against Mitsuba 3 (`llvm_ad_rgb`) on the same machine, in one run,
# on every reference scene of scenes/refs (the furnace rings left out but furnace-0.8): the
# same resolution and spp, three rounds, pathlight and Mitsuba interleaved in each. pathlight:
# whole-process time of `pathlight render --backend cpu` (its default Sobol sampler);
# Mitsuba: render time alone, after one untimed render that compiles its kernels (its
# independent sampler). Quality: each image's relMSE against the scene's converged reference
# (scenes/refs/images, the measure of the reference tests). Printed per scene: the median
# samples/s of each, their ratio, the relMSE of each at equal spp, and the time-to-equal-error
# ratio, (Mitsuba time x Mitsuba relMSE) / (pathlight time x pathlight relMSE): above 1,
# pathlight reaches an error first (Monte Carlo error falls as 1/time). `--baseline BIN` adds
# another pathlight binary (an older build) to each round, and its samples/s, ratio and
# time-to-equal-error ratio to each line: two versions compared in one run, against the same
# Mitsuba rounds. With env-sun and env-sky both run, a last line gives what the environment
# map costs each renderer per sample: env-sun's median time over that of env-sky, its
# constant-sky twin.
#
# On a GPU machine, `--backend gpu --variant cuda_ad_rgb` compares pathlight's GPU backend
# with Mitsuba's CUDA variant; both sides are then timed by render time alone (pathlight's as
# its `render` reports it), since a GPU process's start (driver, shader compilation) dwarfs
# a small render. Every round's times are printed, so the best of them can be read too.
#
# Installs what it needs: Debian's libllvm19 (for an llvm variant) and python3-venv (apt-get,
# as root or with sudo), then Mitsuba and NumPy from pip into a virtual environment
# (MITSUBA_VENV, default bench/.venv). MITSUBA_PYTHON=path/to/python uses a Python that
# already has them instead (nothing installed).
#
#   bash bench/compare-mitsuba.sh [--res N] [--spp N] [--rounds N] [--backend cpu|gpu]
#                                 [--variant V] [--baseline BIN] [SCENE...]
#     defaults: 256x256, 256 spp, 3 rounds, --backend cpu, --variant llvm_ad_rgb, every scene
#   PATHLIGHT=path/to/binary selects the pathlight binary (default: a fresh release build).
set -euo pipefail
cd "$(dirname "$0")/.."
RES=256 SPP=256 ROUNDS=3 BACKEND=cpu VARIANT=llvm_ad_rgb BASELINE= SCENES=()
while [ $# -gt 0 ]; do
    case "$1" in
        --res) RES=$2; shift 2 ;;
        --spp) SPP=$2; shift 2 ;;
        --rounds) ROUNDS=$2; shift 2 ;;
        --backend) BACKEND=$2; shift 2 ;;
        --variant) VARIANT=$2; shift 2 ;;
        --baseline) BASELINE=$2; shift 2 ;;
        *) SCENES+=("$1"); shift ;;
    esac
done
if [ ${#SCENES[@]} -eq 0 ]; then
    for f in scenes/refs/*.toml; do
        name=$(basename "$f" .toml)
        case "$name" in furnace-*) [ "$name" = furnace-0.8 ] || continue ;; esac
        SCENES+=("$name")
    done
fi
VENV=${MITSUBA_VENV:-bench/.venv}
LLVM=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1

sudo_if_needed() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }
if [ -n "${MITSUBA_PYTHON:-}" ]; then
    PY=$MITSUBA_PYTHON
else
    PY=$VENV/bin/python
    if { [[ $VARIANT == llvm* ]] && [ ! -e "$LLVM" ]; } || ! python3 -c 'import venv, ensurepip' 2>/dev/null; then
        sudo_if_needed apt-get update
        sudo_if_needed apt-get install -y libllvm19 python3-venv
    fi
    if [ ! -x "$PY" ]; then
        python3 -m venv "$VENV"
        "$VENV/bin/pip" install --quiet mitsuba numpy
    fi
fi
[ -e "$LLVM" ] && export DRJIT_LIBLLVM_PATH=$LLVM
if [ -z "${PATHLIGHT:-}" ]; then
    cargo build --release --locked --quiet
    PATHLIGHT=./target/release/pathlight
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
device=$("$PATHLIGHT" render scenes/refs/furnace-0.8.toml --backend "$BACKEND" --width 8 --height 8 --spp 1 \
    -o "$out/probe.png" 2>&1 | sed -n 's/^\(backend\|adapter\): \(.*\)/\2/p')
echo "$(date -u +%F), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) cores, pathlight: $device"
echo "load: $(cut -d' ' -f1-3 /proc/loadavg) (a busy machine slows both sides)"
echo "${RES}x${RES}, $SPP spp, $ROUNDS rounds, Mitsuba $VARIANT"
samples=$((RES * RES * SPP))

median() { sort -g | sed -n "$(((ROUNDS + 1) / 2))p"; }

# Renders `scene` with pathlight binary `bin` into `image`; prints its time as the header says.
time_pathlight() {
    local bin=$1 scene=$2 image=$3 start end
    start=$(date +%s.%N)
    "$bin" render "scenes/refs/$scene.toml" --backend "$BACKEND" --width "$RES" --height "$RES" \
        --spp "$SPP" -o "$image" 2>"$out/log" || { cat "$out/log" >&2; exit 1; }
    end=$(date +%s.%N)
    if [ "$BACKEND" = cpu ]; then
        awk "BEGIN { print $end - $start }"
    else
        sed -n 's/.*render \([0-9.]*\) s.*/\1/p' "$out/log" | tail -1
    fi
}

# The relMSE of `image` against the scene's reference, then the Mitsuba image's.
relmse() {
    "$PY" tools/mitsuba_refs.py relmse-of "$1" "$2" "$out/mitsuba.exr" --variant "$VARIANT" |
        "$PY" -c 'import json,sys; print(" ".join(str(json.loads(l)["relmse"]) for l in sys.stdin))'
}

header='%-26s %12s %12s %7s %10s %10s %8s'
[ -n "$BASELINE" ] && header+=' %12s %7s %8s'
# shellcheck disable=SC2059
printf "$header\n" scene "pathlight" "Mitsuba" ratio "relMSE pl" "relMSE mi" "to-error" \
    ${BASELINE:+baseline "ratio" "to-error"}
declare -A pl_median mi_median
for scene in "${SCENES[@]}"; do
    pl_times=() mi_times=() base_times=()
    for round in $(seq "$ROUNDS"); do
        pl_times+=("$(time_pathlight "$PATHLIGHT" "$scene" "$out/pathlight.exr")")
        if [ -n "$BASELINE" ]; then
            base_times+=("$(time_pathlight "$BASELINE" "$scene" "$out/baseline.exr")")
        fi
        json=$("$PY" tools/mitsuba_refs.py time "$scene" --res "$RES" --spp "$SPP" \
            --repeats 1 --save "$out/mitsuba.exr" --variant "$VARIANT")
        mi_times+=("$(echo "$json" | "$PY" -c 'import json,sys; print(json.load(sys.stdin)["median_seconds"])')")
    done
    echo "$scene: pathlight ${pl_times[*]} s,${BASELINE:+ baseline ${base_times[*]} s,} Mitsuba ${mi_times[*]} s" >&2
    pl=$(printf '%s\n' "${pl_times[@]}" | median)
    mi=$(printf '%s\n' "${mi_times[@]}" | median)
    pl_median[$scene]=$pl mi_median[$scene]=$mi
    errors=$(relmse "$scene" "$out/pathlight.exr")
    read -r pl_err mi_err <<<"$errors"
    line=$(awk -v s="$scene" -v n="$samples" -v p="$pl" -v m="$mi" -v pe="$pl_err" -v me="$mi_err" 'BEGIN {
        printf "%-26s %12.2f %12.2f %7.2f %10.5f %10.5f %8.2f", s, n / p / 1e6, n / m / 1e6, m / p, pe, me, (m * me) / (p * pe) }')
    if [ -n "$BASELINE" ]; then
        base=$(printf '%s\n' "${base_times[@]}" | median)
        errors=$(relmse "$scene" "$out/baseline.exr")
        read -r base_err _ <<<"$errors"
        line+=$(awk -v n="$samples" -v b="$base" -v m="$mi" -v be="$base_err" -v me="$mi_err" 'BEGIN {
            printf " %12.2f %7.2f %8.2f", n / b / 1e6, m / b, (m * me) / (b * be) }')
    fi
    echo "$line"
done
if [ -n "${pl_median[env-sun]:-}" ] && [ -n "${pl_median[env-sky]:-}" ]; then
    awk -v p="${pl_median[env-sun]}" -v ps="${pl_median[env-sky]}" -v m="${mi_median[env-sun]}" \
        -v ms="${mi_median[env-sky]}" 'BEGIN {
        printf "the map'"'"'s cost: env-sun'"'"'s time over its constant-sky twin env-sky'"'"'s, pathlight %.2f, Mitsuba %.2f\n", p / ps, m / ms }'
fi
echo "(pathlight: whole process on the CPU backend, render alone on the GPU; Mitsuba: render alone)"
echo "(pathlight and Mitsuba in M samples/s; ratio = pathlight / Mitsuba samples/s; to-error = Mitsuba's time to pathlight's at equal error)"
[ -z "$BASELINE" ] || echo "(baseline: $BASELINE, timed as pathlight in the same rounds; its ratio and to-error against the same Mitsuba)"
