#!/bin/sh
# Merges the shards tools/slurm/sweep-shard.sh wrote into OUT/merged (sweep.json, sweep.md, sweep.png):
#   sbatch --dependency=afterok:<array job id> tools/slurm/merge.sh OUT
# CLOUDBENCH names the binary (default: cloudbench on the PATH).
#SBATCH --job-name=cloudbench-merge
set -eu
out=$1
exec "${CLOUDBENCH:-cloudbench}" merge "$out"/shard-*/sweep.json --out "$out/merged"
