#!/usr/bin/env bash
# Makes pgo/pathlight-cpu.profdata, the profile pathlight-cpu's release build is optimised with
# (tools/rustc-pgo): builds the binary with pathlight-cpu instrumented (in target/pgo-train),
# renders every scene of scenes/ and scenes/refs/ and the default scene with the CPU backend
# at every instruction-set level (the auxiliary images and the independent sampler once),
# small, and merges the counts. Run it after changing the CPU backend and commit the profile
# with the change: a function changed since the profile was made is compiled without one.
# Needs rustup's llvm-tools (`rustup component add llvm-tools`).
#
# On a CPU without a level (x86-64-v4+gfni needs AVX-512 and GFNI), the functions the
# training did not run (that level's row renderer) keep their counts from the committed
# profile, named as they are kept: rustc uses them only while their control flow is unchanged
# (tools/check-pgo.sh fails otherwise; run this on a CPU with every level then). A change that
# keeps a branch but changes how often it is taken leaves those counts stale: train on a CPU
# with every level then too.
#
#   tools/pgo.sh
set -euo pipefail
cd "$(dirname "$0")/.."

profdata=$(ls "$(rustc --print sysroot)"/lib/rustlib/*/bin/llvm-profdata 2>/dev/null | head -n 1)
if [ -z "$profdata" ]; then
    echo "llvm-profdata not found: rustup component add llvm-tools" >&2
    exit 1
fi
counts=$PWD/target/pgo-train/counts
rm -rf "$counts"
PATHLIGHT_PGO=generate=$counts CARGO_TARGET_DIR=target/pgo-train \
    cargo build --release --locked -p pathlight
pathlight=target/pgo-train/release/pathlight
out=target/pgo-train/image.exr
render() {
    local log
    if ! log=$("$pathlight" render "$@" --backend cpu --width 96 --height 96 --spp 16 -o "$out" 2>&1); then
        echo "$log" >&2
        exit 1
    fi
}
# The levels this CPU runs, as pathlight lists them when asked for one it does not know.
runs=$(PATHLIGHT_CPU_LEVEL=none "$pathlight" render --backend cpu -o "$out" 2>&1 || true)
runs=$(sed -n 's/.*this CPU runs the levels //p' <<<"$runs")
if [ -z "$runs" ]; then
    echo "pathlight did not list the levels this CPU runs" >&2
    exit 1
fi
missing=()
for level in baseline x86-64-v3 x86-64-v4+gfni; do
    if [[ ", $runs, " != *", $level, "* ]]; then
        missing+=("$level")
        continue
    fi
    export PATHLIGHT_CPU_LEVEL=$level
    render # the default scene
    for scene in scenes/*.toml scenes/refs/*.toml; do
        render "$scene"
    done
    render --aov albedo,normal
    render --sampler independent
done
if [ ${#missing[@]} -eq 0 ]; then
    "$profdata" merge --sparse -o pgo/pathlight-cpu.profdata "$counts"
else
    if [ ! -f pgo/pathlight-cpu.profdata ]; then
        echo "this CPU lacks ${missing[*]} and there is no profile to keep its counts from" >&2
        exit 1
    fi
    # Not sparse: every instrumented function, those never run with zero counts.
    "$profdata" merge --text -o target/pgo-train/trained.proftext "$counts"
    "$profdata" merge --text -o target/pgo-train/committed.proftext pgo/pathlight-cpu.profdata
    echo "this CPU lacks ${missing[*]}: the functions not run keep the committed profile's counts"
    python3 tools/pgo_keep.py target/pgo-train/committed.proftext \
        target/pgo-train/trained.proftext >target/pgo-train/kept.proftext
    "$profdata" merge --sparse -o pgo/pathlight-cpu.profdata \
        target/pgo-train/trained.proftext target/pgo-train/kept.proftext
fi
rustc -vV | sed -n 's/^LLVM version: //p' > pgo/llvm-version
echo "pgo/pathlight-cpu.profdata: $(du -h pgo/pathlight-cpu.profdata | cut -f1)," \
    "LLVM $(cat pgo/llvm-version)"
