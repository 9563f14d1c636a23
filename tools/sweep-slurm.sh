#!/usr/bin/env bash
# A heliodon sweep as a Slurm job array: one shard per array task, then one
# dependent job that merges the parts into the unsharded output.
#
# Usage: tools/sweep-slurm.sh SHARDS OUT_DIR -- SWEEP_ARGS...
#   e.g. tools/sweep-slurm.sh 16 runs/prismatic -- scene.toml --material upper \
#          --vary 'facet_angles[0]=0..60:5' --vary 'facet_angles[1]=0..60:5' \
#          --all-sensors --weather chicago.epw
#
# Each task runs `heliodon sweep SWEEP_ARGS --shard K/SHARDS --format csv`
# into OUT_DIR/part-K.csv (every task precomputes the scene's light once:
# give the tasks a shared HELIODON_CACHE_DIR and the first one's work is
# reused by the rest); the merge job writes OUT_DIR/sweep.csv and the heat
# map OUT_DIR/sweep.png. Set HELIODON to the executable's path if it is not
# on PATH, and SBATCH_ARGS for the partition, time and memory limits.
# Without Slurm (no sbatch on PATH) the shards run one after another here,
# which is also how the script is tested.
set -euo pipefail
if [ $# -lt 4 ] || [ "$3" != "--" ]; then
    echo "usage: $0 SHARDS OUT_DIR -- SWEEP_ARGS..." >&2
    exit 2
fi
shards=$1
out=$2
shift 3
heliodon=${HELIODON:-heliodon}
mkdir -p "$out"
args=$(printf '%q ' "$@")
task="$heliodon sweep $args --shard \${K}/$shards --format csv > $out/part-\${K}.csv"
merge="$heliodon sweep-merge $out/part-*.csv --out $out/sweep.png > $out/sweep.csv"
if command -v sbatch > /dev/null; then
    array=$(sbatch --parsable ${SBATCH_ARGS:-} --array=1-"$shards" --output="$out/task-%a.log" \
        --wrap="K=\$SLURM_ARRAY_TASK_ID; $task")
    sbatch ${SBATCH_ARGS:-} --dependency=afterok:"$array" --output="$out/merge.log" --wrap="$merge"
    echo "submitted array job $array ($shards shards) and its merge"
else
    for K in $(seq 1 "$shards"); do
        eval "$task"
    done
    eval "$merge"
    echo "ran $shards shards here (no sbatch); wrote $out/sweep.csv and $out/sweep.png"
fi
