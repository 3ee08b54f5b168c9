#!/usr/bin/env bash
# The denoiser's quality and cost: for two reference scenes (256x256, against their converged
# Mitsuba 3 images in scenes/refs/images), the relMSE of the raw image and of the images
# denoised in `final` and `fast` mode at 4, 16, 64 and 256 spp (CPU backend, seed 0, albedo
# and normal rendered with the image), and the denoiser's time at 500x500 and 1920x1080.
# Needs a release build, OIDN (tools/get-oidn.sh) and python3 with numpy and OpenEXR
# (`pip install numpy OpenEXR`).
#
#   bench/denoise.sh [path/to/pathlight]
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-target/release/pathlight}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

relmse() {  # image reference -> relMSE, as Film::relmse computes it
    python3 - "$1" "$2" <<'PY'
import sys, numpy as np, OpenEXR
def rgb(path):
    channels = OpenEXR.File(path).channels()
    if "RGB" in channels:
        return np.asarray(channels["RGB"].pixels, dtype=np.float64)
    return np.stack([np.asarray(channels[c].pixels, dtype=np.float64) for c in "RGB"], -1)
x, r = rgb(sys.argv[1]), rgb(sys.argv[2])
print(f"{np.mean((x - r) ** 2 / (r * r + 0.01)):.5f}")
PY
}

echo "| scene | spp | raw | final | fast |"
echo "| --- | --- | --- | --- | --- |"
for scene in cornell-spheres cornell-materials; do
    ref=scenes/refs/images/$scene.exr
    for spp in 4 16 64 256; do
        "$bin" render scenes/refs/$scene.toml --backend cpu --spp "$spp" --aov albedo,normal \
            -o "$out/raw.exr" 2>/dev/null
        "$bin" denoise "$out/raw.exr" --mode final -o "$out/final.exr" 2>/dev/null
        "$bin" denoise "$out/raw.exr" --mode fast -o "$out/fast.exr" 2>/dev/null
        echo "| $scene | $spp | $(relmse "$out/raw.exr" "$ref") | $(relmse "$out/final.exr" "$ref") | $(relmse "$out/fast.exr" "$ref") |"
    done
done

echo
echo "| size | final | fast |"
echo "| --- | --- | --- |"
for size in "500 500" "1920 1080"; do
    set -- $size
    "$bin" render --backend cpu --width "$1" --height "$2" --spp 1 --aov albedo,normal \
        -o "$out/big.exr" 2>/dev/null
    times=()
    for mode in final fast; do
        # The denoiser's own time, as it reports it (the process also reads and writes EXRs).
        t=$("$bin" denoise "$out/big.exr" --mode $mode -o "$out/dn.exr" 2>&1 | sed -n 's/^denoised .* in \([0-9.]*\) s$/\1/p')
        times+=("$t s")
    done
    echo "| $1x$2 | ${times[0]} | ${times[1]} |"
done
