#!/usr/bin/env bash
# Makes pgo/pathlight-cpu.profdata, the profile pathlight-cpu's release build is optimised with
# (tools/rustc-pgo): builds the binary with pathlight-cpu instrumented (in target/pgo-train),
# renders every scene of scenes/ and scenes/refs/ and the default scene with the CPU backend
# at every instruction-set level (the auxiliary images and the independent sampler once),
# small, and merges the counts. Run it after changing the CPU backend and commit the profile
# with the change: a function changed since the profile was made is compiled without one.
# Needs rustup's llvm-tools (`rustup component add llvm-tools`) and a CPU with AVX-512 and
# GFNI: a level the training never ran would be laid out as cold code.
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
for level in baseline x86-64-v3 x86-64-v4+gfni; do
    export PATHLIGHT_CPU_LEVEL=$level
    render # the default scene; refused here when this CPU lacks the level
    for scene in scenes/*.toml scenes/refs/*.toml; do
        render "$scene"
    done
    render --aov albedo,normal
    render --sampler independent
done
"$profdata" merge --sparse -o pgo/pathlight-cpu.profdata "$counts"
rustc -vV | sed -n 's/^LLVM version: //p' > pgo/llvm-version
echo "pgo/pathlight-cpu.profdata: $(du -h pgo/pathlight-cpu.profdata | cut -f1)," \
    "LLVM $(cat pgo/llvm-version)"
