#!/usr/bin/env bash
# Checks that the CPU backend's path tracer is inlined whole into its row renderer.
# `render_row` is compiled once per instruction-set level (crates/cpu/src/row.rs); a function
# it calls that the compiler leaves out of line is compiled for the baseline instead (SSE2: no
# AVX, a libm call for every `floor`) and costs a call that saves every live vector register
# (texture lookups were left out so: 17% of textured-sphere's profile). Builds the release
# binary and fails, naming them, when it holds a function of a module the row runs (every
# module of pathlight-cpu but the renderer's setup in lib.rs, `cpu_scene`, `display` and the
# level's choice in `row`), apart from `textures::alpha_stops`, the alpha test of cut-out
# triangles, left out on purpose (rare, and large), `Tracer::new`, which a thread calls
# once, outside the row, and `ShadingLanes::default`, which a row calls once, before its
# loop; and when the row renderers call any function directly (naming the source lines),
# which finds generic functions of other crates left out of line for them.
#
#   tools/check-inlined.sh
set -euo pipefail
cd "$(dirname "$0")/.."

cargo build --release --locked -p pathlight
hot='area_light|bsdf_lanes|bvh|camera|diffuse|environment|glass|glossy|integrator|intersect'
hot+='|light_lanes|light_sample|lights|lobes|material|metal_rough|microfacet|packet|point_light|prefetch'
hot+='|sampler|sampling|sheen|soa|sun_light|surface|textures|tracer'
# Function symbols (text, weak), demangled, without their hashes: those of a hot module, or
# of `row` but the level's choice (`InstructionSet`, `UnknownLevel`) and the per-level entry
# points.
out_of_line=$(nm -C target/release/pathlight |
    awk '$2 ~ /^[tTwW]$/ { $1 = ""; $2 = ""; sub(/^ +/, ""); print }' |
    sed 's/::h[0-9a-f]\{16\}$//' |
    grep -P "^<?pathlight_cpu::(($hot)::|row::(?!InstructionSet::|UnknownLevel |render_row_with$|render_row_x86_64_))" |
    grep -Ev '^<?pathlight_cpu::(textures::alpha_stops|tracer::Tracer::new|integrator::ShadingLanes as core::default::Default>::default)$' |
    sort -u || true)
if [ -n "$out_of_line" ]; then
    echo "functions of the CPU path tracer left out of line (compiled for the baseline);" >&2
    echo "mark them #[inline(always)]:" >&2
    echo "$out_of_line" >&2
    exit 1
fi
# What the row renderers call directly, by source line: a generic function of another crate
# instantiated for them (`array::map` and `array::from_fn` closures were) is left out of line
# under another crate's name, which the check above cannot see. Calls through the PLT
# (libc, libm) are indirect and allowed.
binary=target/release/pathlight
called=
while read -r start size; do
    stop=$(printf '0x%x' $((0x$start + 0x$size)))
    called+=$(objdump -d --no-show-raw-insn --start-address="0x$start" --stop-address="$stop" "$binary" |
        awk '$2 == "call" && $3 ~ /^[0-9a-f]+$/ { sub(":", "", $1); print $1 }' |
        while read -r address; do
            addr2line -e "$binary" -i "0x$address" | grep -v '^/rustc/' | head -n 1
        done)$'\n'
done < <(nm -S "$binary" | awk '$4 ~ /render_row_x86_64_/ { print $1, $2 }')
called=$(sort -u <<<"$called" | sed '/^$/d')
if [ -n "$called" ]; then
    echo "the row renderer calls functions left out of line (compiled for the baseline) at:" >&2
    echo "$called" >&2
    exit 1
fi
echo "the CPU path tracer is inlined into its row renderer"
