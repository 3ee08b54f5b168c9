#!/usr/bin/env bash
# Renders a scene as a Slurm job array of TASKS parts and merges them once all succeed:
#
#   examples/slurm/submit.sh TASKS OUT_DIR [pathlight render options...]
#   examples/slurm/submit.sh 16 /shared/renders/room scenes/default.toml --spp 4096 --backend cpu
#
# OUT_DIR must be on a file system every node sees. $PATHLIGHT names the binary (default:
# `pathlight` on the PATH); $IMAGE the merged image's name in OUT_DIR (default image.exr).
# Extra `sbatch` options (partition, time limit, GPUs) go in $SBATCH_OPTS. Prints the two
# job ids.
set -euo pipefail
tasks=$1
out=$(realpath "$2")
shift 2
here=$(dirname "$(realpath "$0")")
mkdir -p "$out"
export PATHLIGHT=${PATHLIGHT:-$(command -v pathlight)}
export OUT=$out IMAGE=${IMAGE:-image.exr} PATHLIGHT_ARGS="$*"
# shellcheck disable=SC2086 # $SBATCH_OPTS holds several options
parts=$(sbatch --parsable ${SBATCH_OPTS:-} --array="0-$((tasks - 1))" \
    --output="$out/part-%a.log" --export=ALL "$here/render-array.sbatch")
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_OPTS:-} --dependency="afterok:$parts" \
    --output="$out/merge.log" --export=ALL "$here/merge.sbatch")
echo "parts: job $parts ($tasks tasks); merge: job $merge -> $out/$IMAGE"
