#!/usr/bin/env bash
# Slurm job-array example: N shards of one batch, then one table.
#   sbatch --array=1-8 scripts/slurm_batch.sh BATCH.yaml OUTROOT
#   (after all finish)  build/celc table OUTROOT/shard_* -o OUTROOT/table
# Each array task K runs `celc batch --shard K/N` into OUTROOT/shard_K; every
# sequence's windows with index % N == K-1 land there, and `celc table` merges
# the shards of each sequence (same folder name) into the paper's tables.
#SBATCH --job-name=celc
#SBATCH --cpus-per-task=2
#SBATCH --time=04:00:00
set -euo pipefail
batch="$1"
outroot="$2"
k="${SLURM_ARRAY_TASK_ID:?run as a Slurm array job}"
n="${SLURM_ARRAY_TASK_COUNT:?run as a Slurm array job}"
root="$(cd "$(dirname "$0")/.." && pwd)"
"${CELC_BUILD_DIR:-$root/build}/celc" batch "$batch" -o "$outroot/shard_$k" \
  --shard "$k/$n" --threads "${SLURM_CPUS_PER_TASK:-2}" --resume -q
