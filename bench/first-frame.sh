#!/usr/bin/env bash
# Time to the first frame and peak memory of one big mesh: pathlight's CPU backend (the mesh
# as a GLB) against Mitsuba 3 `llvm_ad_rgb` (the same mesh as a binary PLY), each a whole
# process (Mitsuba's includes starting Python and compiling its kernels), one 256x256 frame at
# 1 spp, `/usr/bin/time` for seconds and peak resident memory, rounds interleaved. The meshes
# are `tools/forest_gltf.py`'s bumpy sphere: 1m = 1,048,576 triangles, 4m = 4,194,304, 16m
# = 16,777,216 (written once into bench/.first-frame, about 30 bytes a triangle each).
# Needs a release build (`cargo build --release`) and the virtual environment
# bench/compare-mitsuba.sh makes (MITSUBA_VENV, default bench/.venv, with mitsuba and numpy).
# --baseline BIN adds another pathlight binary (an older build) to each round.
#
#   bash bench/first-frame.sh [--rounds N] [--baseline BIN] [SIZE...]
#       (SIZE: 1m 4m 16m; default all three)
set -euo pipefail
cd "$(dirname "$0")/.."

ROUNDS=3
SIZES=()
BASELINE=
while [ $# -gt 0 ]; do
    case "$1" in
        --rounds) ROUNDS=$2; shift 2 ;;
        --baseline) BASELINE=$2; shift 2 ;;
        1m|4m|16m) SIZES+=("$1"); shift ;;
        *) echo "usage: bash bench/first-frame.sh [--rounds N] [--baseline BIN] [1m] [4m] [16m]" >&2
           exit 2 ;;
    esac
done
[ ${#SIZES[@]} -gt 0 ] || SIZES=(1m 4m 16m)
VENV=${MITSUBA_VENV:-bench/.venv}
PY="$VENV/bin/python"
if ! "$PY" -c 'import mitsuba, numpy' 2>/dev/null; then
    echo "no Mitsuba in $VENV: run bench/compare-mitsuba.sh once, or set MITSUBA_VENV" >&2
    exit 1
fi
BIN=target/release/pathlight
[ -x "$BIN" ] || { echo "no $BIN: cargo build --release first" >&2; exit 1; }
DIR=bench/.first-frame
mkdir -p "$DIR"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

MITSUBA='
import sys
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
scene = mi.load_dict({
    "type": "scene",
    "integrator": {"type": "path", "max_depth": 8},
    "sensor": {
        "type": "perspective", "fov": 40,
        "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0.5, 3.5], target=[0, 0, 0], up=[0, 1, 0]),
        "film": {"type": "hdrfilm", "width": 256, "height": 256},
    },
    "sphere": {"type": "ply", "filename": sys.argv[1], "bsdf": {"type": "diffuse"}},
    "sky": {"type": "constant"},
})
mi.util.write_bitmap(sys.argv[2], mi.render(scene, spp=1))
'

# `/usr/bin/time` of a command: "seconds peak-MiB".
measure() {
    /usr/bin/time -f '%e %M' -o "$out/time" "$@" >/dev/null 2>&1
    awk '{printf "%.2f %.0f", $1, $2 / 1024}' "$out/time"
}

row() { printf '%-5s %-10s %10s %10s\n' "$@"; }
row mesh program seconds "peak MiB"
for size in "${SIZES[@]}"; do
    case $size in
        1m) grid="1024 512" ;;
        4m) grid="2048 1024" ;;
        16m) grid="4096 2048" ;;
    esac
    read -r segments rings <<<"$grid"
    if [ ! -f "$DIR/$size.glb" ] || [ ! -f "$DIR/$size.ply" ]; then
        "$PY" tools/forest_gltf.py "$DIR/$size.glb" --placements 1 \
            --segments "$segments" --rings "$rings" --ply "$DIR/$size.ply" >/dev/null
    fi
    for round in $(seq "$ROUNDS"); do
        for bin in "$BIN" ${BASELINE:+"$BASELINE"}; do
            name=pathlight
            [ "$bin" = "$BIN" ] || name=baseline
            row "$size" "$name" $(measure "$bin" render "$DIR/$size.glb" --backend cpu \
                --width 256 --height 256 --spp 1 -o "$out/pathlight.png")
        done
        row "$size" Mitsuba $(measure "$PY" -c "$MITSUBA" "$DIR/$size.ply" "$out/mitsuba.exr")
    done
done
