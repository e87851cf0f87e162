#!/bin/sh
# One share of a sharded sweep, as a Slurm job array task (docs/cli.md, "Sharded sweeps on a cluster"):
#   sbatch --array=1-N tools/slurm/sweep-shard.sh OUT SCENE [sweep options...]
# Task I of N writes OUT/shard-I/sweep.json (sweep --shard I/N); tools/slurm/merge.sh merges them once every task
# has ended well: sbatch --dependency=afterok:<array job id> tools/slurm/merge.sh OUT
# CLOUDBENCH names the binary (default: cloudbench on the PATH).
#SBATCH --job-name=cloudbench-sweep
set -eu
out=$1
scene=$2
shift 2
: "${SLURM_ARRAY_TASK_ID:?submit as a job array: sbatch --array=1-N}"
: "${SLURM_ARRAY_TASK_COUNT:?submit as a job array: sbatch --array=1-N}"
exec "${CLOUDBENCH:-cloudbench}" sweep "$scene" "$@" --quiet \
    --shard "$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT" --out "$out/shard-$SLURM_ARRAY_TASK_ID"
