#!/usr/bin/env bash
# Run an autobal study on Slurm: an array job with one shard per task, then a
# merge job that starts only when every shard succeeded. If a shard fails
# (or is cancelled), Slurm cancels the merge job (--kill-on-invalid-dep=yes)
# instead of leaving it pending for ever (DependencyNeverSatisfied).
#
#   deploy/slurm/submit.sh STUDY.toml SHARDS [CPUS_PER_TASK]
#
# Environment: STUDY_BIN (default: study on PATH); RESULTS_DIR (default
# results/<study file name>, which is where a study without `name` and
# `output` keys writes; set it when the study names another folder).
# Prints the two job ids. Run it from the folder the results should go under.
set -euo pipefail
if [ $# -lt 2 ]; then
  sed -n '2,12p' "$0" >&2
  exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
study=$(realpath "$1")
shards=$2
cpus=${3:-1}
export STUDY=$study
export SHARDS=$shards
export STUDY_BIN=${STUDY_BIN:-study}
export RESULTS_DIR=${RESULTS_DIR:-$PWD/results/$(basename "$study" .toml)}
array=$(sbatch --parsable --array=1-"$shards" --cpus-per-task="$cpus" \
  --export=ALL "$here/study-array.sbatch")
merge=$(sbatch --parsable --dependency=afterok:"$array" \
  --kill-on-invalid-dep=yes --export=ALL "$here/study-merge.sbatch")
echo "array job $array ($shards shards), merge job $merge"
