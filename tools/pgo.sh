#!/usr/bin/env bash
# Makes pgo/pathlight-cpu.profdata, the profile pathlight-cpu's release build is optimised with
# (tools/rustc-pgo): builds the binary with pathlight-cpu instrumented (in target/pgo-train),
# renders every scene of scenes/ and scenes/refs/ and the default scene with the CPU backend
# at every instruction-set level (the auxiliary images and the independent sampler once),
# small, and merges the counts. Run it after changing the CPU backend and commit the profile
# with the change: a function changed since the profile was made is compiled without one.
# It builds no release binary: `cargo build --release` afterwards builds one with the new
# profile (the one in target/release before it ran was built with the old).
# Needs rustup's llvm-tools (`rustup component add llvm-tools`).
#
# On a CPU with x86-64-v3 but without x86-64-v4+gfni (AVX-512 and GFNI), that level's row
# renderer is trained by a stand-in: the binary built again with it compiled to x86-64-v3 code
# from the level's own optimised module (tools/pgo-stand-in), whose counts belong to the
# control flow the release build compiles (tools/check-pgo.sh checks that) and whose images
# are the level's bit for bit (checked here). On a CPU without x86-64-v3, the functions the
# training did not run keep their counts from the committed profile: rustc uses them only
# while their control flow is unchanged (tools/check-pgo.sh fails otherwise).
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
pathlight=target/pgo-train/release/pathlight
out=target/pgo-train/image.exr
# Builds the instrumented binary, PATHLIGHT_PGO=$1 (tools/rustc-pgo).
build() {
    PATHLIGHT_PGO=$1 CARGO_TARGET_DIR=target/pgo-train cargo build --release --locked -p pathlight
}
render() {
    local log
    if ! log=$("$pathlight" render "$@" --backend cpu --width 96 --height 96 --spp 16 -o "$out" 2>&1); then
        echo "$log" >&2
        exit 1
    fi
}
# Renders the training scenes at level $1, the counts into directory $2.
train() {
    export PATHLIGHT_CPU_LEVEL=$1 LLVM_PROFILE_FILE=$2/default_%m.profraw
    render # the default scene
    for scene in scenes/*.toml scenes/refs/*.toml; do
        render "$scene"
    done
    render --aov albedo,normal
    render --sampler independent
    unset PATHLIGHT_CPU_LEVEL LLVM_PROFILE_FILE
}
build "generate=$counts/levels"
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
    else
        train "$level" "$counts/levels"
    fi
done
# Keeps, beside the training's counts, those of profile $1 for what the training did not run.
keep_from() {
    # Not sparse: every instrumented function, those never run with zero counts.
    "$profdata" merge --text -o target/pgo-train/trained.proftext "$counts/levels"
    "$profdata" merge --text -o target/pgo-train/kept-from.proftext "$1"
    python3 tools/pgo_keep.py target/pgo-train/kept-from.proftext \
        target/pgo-train/trained.proftext >target/pgo-train/kept.proftext
    "$profdata" merge --sparse -o pgo/pathlight-cpu.profdata \
        target/pgo-train/trained.proftext target/pgo-train/kept.proftext
}
if [ ${#missing[@]} -eq 0 ]; then
    "$profdata" merge --sparse -o pgo/pathlight-cpu.profdata "$counts/levels"
elif [ "${missing[*]}" = x86-64-v4+gfni ]; then
    echo "this CPU lacks x86-64-v4+gfni: its row renderer is trained by a stand-in"
    build "stand-in=$counts/stand-in"
    # Every level renders the same image bit for bit: the stand-in too, or its code is wrong.
    for level in x86-64-v3 x86-64-v4+gfni; do
        out=target/pgo-train/$level.exr PATHLIGHT_CPU_LEVEL=$level \
            LLVM_PROFILE_FILE=$counts/check/%m.profraw render scenes/refs/cornell-materials.toml
    done
    if ! cmp -s target/pgo-train/x86-64-v3.exr target/pgo-train/x86-64-v4+gfni.exr; then
        echo "the stand-in's x86-64-v4+gfni image differs from x86-64-v3's" >&2
        exit 1
    fi
    train x86-64-v4+gfni "$counts/stand-in"
    "$profdata" merge -o target/pgo-train/stand-in.profdata "$counts/stand-in"
    keep_from target/pgo-train/stand-in.profdata
else
    if [ ! -f pgo/pathlight-cpu.profdata ]; then
        echo "this CPU lacks ${missing[*]} and there is no profile to keep its counts from" >&2
        exit 1
    fi
    echo "this CPU lacks ${missing[*]}: the functions not run keep the committed profile's counts"
    keep_from pgo/pathlight-cpu.profdata
fi
rustc -vV | sed -n 's/^LLVM version: //p' > pgo/llvm-version
echo "pgo/pathlight-cpu.profdata: $(du -h pgo/pathlight-cpu.profdata | cut -f1)," \
    "LLVM $(cat pgo/llvm-version); \`cargo build --release\` builds with it"
