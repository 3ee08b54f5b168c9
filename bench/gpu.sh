#!/usr/bin/env bash
# pathlight's GPU backend on the standard set of measurements, printed as one table, so every
# GPU figure in BENCHMARKS.md is taken the same way. Several binaries (versions) are compared
# interleaved: each round runs every case with every binary in turn.
#
# Cases (names for --cases):
#   default       the built-in default scene, 500x500, max_depth 8 (`pathlight bench`)
#   no-vase       the same without the vase (scenes/default.toml less its [[revolve]])
#   1080p         the default scene at 1920x1080
#   depth-1/2/4   the default scene at max_depth 1 (camera rays), 2 (direct light), 4
#   1m-triangles  bench/scenes/million-triangles.toml, 500x500
#   instanced     scenes/instances.toml (one mesh placed 11 times)
#   flattened     bench/scenes/instances-flat.toml (the same placements as 11 meshes)
#   cornell-512   scenes/refs/cornell-spheres.toml, 512x512, 64 spp, `pathlight render`:
#                 whole-process seconds, and the render alone as pathlight reports it
# bench cases print fps (one sample per pixel per frame) and G rays/s; each cell is the
# median over the rounds with the range beside it, and the kernel each round rendered with
# (`auto` picks one per run). A case a binary cannot run prints "-".
#
#   bash bench/gpu.sh [--rounds N] [--frames N] [--cases LIST] [BIN...]
#     BIN: pathlight binaries (default: a fresh release build), each optionally with options
#     for all its runs in the same word, e.g. "target/release/pathlight --gpu-kernel
#     wavefront" beside "target/release/pathlight --gpu-kernel megakernel" (a bare binary
#     takes its default kernel, `auto` since 3c468f3); --rounds 2; --frames 3000
#     (the 500x500 cases; 1080p takes a tenth, 1m-triangles a third); --cases: a
#     comma-separated subset of the names above.
set -uo pipefail
cd "$(dirname "$0")/.."
ROUNDS=2 FRAMES=3000 BINS=()
CASES=default,no-vase,1080p,depth-1,depth-2,depth-4,1m-triangles,instanced,flattened,cornell-512
while [ $# -gt 0 ]; do
    case "$1" in
        --rounds) ROUNDS=$2; shift 2 ;;
        --frames) FRAMES=$2; shift 2 ;;
        --cases) CASES=$2; shift 2 ;;
        *) BINS+=("$1"); shift ;;
    esac
done
if [ ${#BINS[@]} -eq 0 ]; then
    cargo build --release --locked --quiet -p pathlight || exit 1
    BINS=(target/release/pathlight)
fi
IFS=, read -r -a CASE_LIST <<<"$CASES"
out=$(mktemp -d)
# The default scene without the vase (every table block but the one naming it), beside the
# default scene so that its textures' relative paths hold.
no_vase=$(mktemp --suffix=.toml scenes/no-vase.XXXXXX)
trap 'rm -rf "$out" "$no_vase"' EXIT
awk 'function flush() { if (block !~ /name = "vase"/) printf "%s", block; block = "" }
     /^\[/ { flush() } { block = block $0 "\n" } END { flush() }' scenes/default.toml >"$no_vase"

args_of() {
    case $1 in
        default) echo "bench --frames $FRAMES" ;;
        no-vase) echo "bench $no_vase --frames $FRAMES" ;;
        1080p) echo "bench --width 1920 --height 1080 --frames $((FRAMES / 10))" ;;
        depth-[0-9]*) echo "bench --max-depth ${1#depth-} --frames $FRAMES" ;;
        1m-triangles) echo "bench bench/scenes/million-triangles.toml --frames $((FRAMES / 3))" ;;
        instanced) echo "bench scenes/instances.toml --frames $FRAMES" ;;
        flattened) echo "bench bench/scenes/instances-flat.toml --frames $FRAMES" ;;
        cornell-512) echo "render scenes/refs/cornell-spheres.toml --width 512 --height 512 --spp 64 -o $out/cornell.exr" ;;
        *) echo "unknown case $1" >&2; exit 2 ;;
    esac
}

echo "$(date -u +%F), $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null || echo 'no nvidia-smi'), $(nproc) cores"
for i in "${!BINS[@]}"; do
    read -r -a cmd <<<"${BINS[$i]}"
    echo "binary $i: ${BINS[$i]} ($("${cmd[0]}" --version 2>&1))"
done

for round in $(seq "$ROUNDS"); do
    for case in "${CASE_LIST[@]}"; do
        read -r -a args <<<"$(args_of "$case")"
        for i in "${!BINS[@]}"; do
            log="$out/log"
            start=$(date +%s.%N)
            read -r -a cmd <<<"${BINS[$i]}"
            if timeout 120 "${cmd[0]}" "${args[@]}" "${cmd[@]:1}" >"$log" 2>&1; then
                end=$(date +%s.%N)
                if [ "$case" = cornell-512 ]; then
                    render=$(sed -n 's/.*render \([0-9.]*\) s.*/\1/p' "$log" | tail -1)
                    echo "$(awk "BEGIN { print $end - $start }") ${render:-nan}" >>"$out/$case.$i"
                else
                    fps=$(awk '$1 == "fps" { print $2 }' "$log")
                    rays=$(awk '$1 == "rays/s" { print $2 / 1000 }' "$log")
                    # The kernel the run rendered with (M megakernel, W wavefront).
                    kernel=$(sed -n 's/^settings.*, kernel \([mw]\).*/\1/p' "$log" | tr mw MW)
                    echo "${fps:-nan} ${rays:-nan} ${kernel:--}" >>"$out/$case.$i"
                fi
                if [ "$round" = 1 ] && [ "$case" = "${CASE_LIST[0]}" ]; then
                    grep -m1 -E '^device|backend:' "$log" | sed "s/^/binary $i: /"
                    grep -q 'cpu backend' "$log" && echo "binary $i: warning: no hardware GPU, these are the CPU backend's figures"
                fi
            else
                echo "binary $i failed $case: $(tail -1 "$log")"
            fi
        done
    done
done

# Median and range of column $2 of a result file.
stat_of() {
    [ -s "$1" ] || { echo "-"; return; }
    cut -d' ' -f"$2" "$1" | sort -g | awk -v fmt="$3" '{ v[NR] = $1 }
        END { printf fmt, v[int((NR + 1) / 2)], v[1], v[NR] }'
}
printf '\n%-14s' case
for i in "${!BINS[@]}"; do printf ' | %-30s' "binary $i"; done
printf '\n'
for case in "${CASE_LIST[@]}"; do
    printf '%-14s' "$case"
    for i in "${!BINS[@]}"; do
        if [ "$case" = cornell-512 ]; then
            cell="$(stat_of "$out/$case.$i" 1 '%.2f s (%.2f-%.2f)'), render $(stat_of "$out/$case.$i" 2 '%.3f s')"
        else
            kernels=$(cut -d' ' -f3 "$out/$case.$i" 2>/dev/null | tr -d '\n')
            cell="$(stat_of "$out/$case.$i" 1 '%.0f fps (%.0f-%.0f)'), $(stat_of "$out/$case.$i" 2 '%.2f G rays/s') ${kernels}"
        fi
        printf ' | %-30s' "$cell"
    done
    printf '\n'
done
echo "(median over $ROUNDS rounds, range in brackets, then the kernel of each round: M megakernel,"
echo " W wavefront; cornell-512: whole process, then the render alone)"
