#!/usr/bin/env bash
# Slurm job-array example: N shards of one batch, then one table.
#   sbatch --array=1-8 scripts/slurm_batch.sh BATCH.yaml OUTROOT [N]
#   (after all finish)  build/celc table OUTROOT/shard_* -o OUTROOT/table
# Each array task K runs `celc batch --shard K/N` into OUTROOT/shard_K; every
# sequence's windows with index % N == K-1 land there, and `celc table` merges
# the shards of each sequence (same folder name) into the paper's tables.
# (scripts/slurm_test.sh runs this on a one-node Slurm and checks the rows.)
#
# Array ids: K is SLURM_ARRAY_TASK_ID and must be 1..N. N is the third
# argument, or else the array's size, which then must be exactly 1..N
# (--array=1-8 or 1-8%2, not 0-7 or 1-8:2); give N to re-run some shards of
# an earlier array, e.g. `sbatch --array=3,5 scripts/slurm_batch.sh B O 8`.
#
# sbatch runs a copy of this file from its spool folder, so the repository
# is not found from "$0": it is CELC_ROOT, else the folder of the script as
# submitted (`scontrol show job`), else the submit folder (SLURM_SUBMIT_DIR).
# celc is CELC_BUILD_DIR/celc (default ROOT/build/celc). sbatch passes the
# submitting shell's environment (CELC_ROOT, CELC_BUILD_DIR, CELC_NO_PLOTS).
# Relative BATCH and OUTROOT are relative to the submit folder.
#SBATCH --job-name=celc
#SBATCH --cpus-per-task=2
#SBATCH --time=04:00:00
set -euo pipefail
die() { echo "slurm_batch.sh: error: $*" >&2; exit 2; }
if [ $# -lt 2 ] || [ $# -gt 3 ]; then die "usage: sbatch --array=1-N $0 BATCH.yaml OUTROOT [N]"; fi
batch="$1"
outroot="$2"
k="${SLURM_ARRAY_TASK_ID:?run as a Slurm array job (sbatch --array=1-N)}"
if [ $# -eq 3 ]; then
  n="$3"
else
  n="${SLURM_ARRAY_TASK_COUNT:?run as a Slurm array job (sbatch --array=1-N)}"
  if [ "${SLURM_ARRAY_TASK_MIN:-1}" != 1 ] || [ "${SLURM_ARRAY_TASK_MAX:-$n}" != "$n" ]; then
    die "array ids ${SLURM_ARRAY_TASK_MIN:-?}-${SLURM_ARRAY_TASK_MAX:-?} (${n} tasks) are not 1..${n}; submit --array=1-N or give N as the third argument"
  fi
fi
case "$n" in '' | *[!0-9]* | 0) die "N '$n' is not a positive whole number" ;; esac
if [ "$k" -lt 1 ] || [ "$k" -gt "$n" ]; then die "array task id $k is outside 1..$n"; fi

is_root() { [ -n "$1" ] && [ -f "$1/scripts/slurm_batch.sh" ] && [ -f "$1/CMakeLists.txt" ]; }
root=""
parent_of() { (cd "$(dirname "$1")/.." 2>/dev/null && pwd) || true; }  # FILE -> the folder above its folder
candidates=("${CELC_ROOT:-}" "$(parent_of "$0")")
how=(CELC_ROOT "the script's folder")
if [ -n "${SLURM_JOB_ID:-}" ] && command -v scontrol >/dev/null; then
  cmd="$(scontrol show job -o "$SLURM_JOB_ID" 2>/dev/null | grep -o 'Command=[^ ]*' | head -n1 || true)"
  cmd="${cmd#Command=}"
  if [ -n "$cmd" ]; then
    candidates+=("$(parent_of "$cmd")")
    how+=("the submitted script's folder")
  fi
fi
candidates+=("${SLURM_SUBMIT_DIR:-}")
how+=(SLURM_SUBMIT_DIR)
found="CELC_BUILD_DIR"
for i in "${!candidates[@]}"; do
  if is_root "${candidates[$i]}"; then
    root="${candidates[$i]}" found="${how[$i]}"
    break
  fi
done
[ -n "$root" ] || [ -n "${CELC_BUILD_DIR:-}" ] ||
  die "cannot find the celc repository (tried: ${candidates[*]}); set CELC_ROOT or CELC_BUILD_DIR"
celc="${CELC_BUILD_DIR:-$root/build}/celc"
[ -x "$celc" ] || die "$celc is not an executable (build it, or set CELC_BUILD_DIR)"
echo "slurm_batch.sh: shard $k/$n of $batch into $outroot/shard_$k with $celc (repository from $found)" >&2
"$celc" batch "$batch" -o "$outroot/shard_$k" \
  --shard "$k/$n" --threads "${SLURM_CPUS_PER_TASK:-2}" --resume -q
