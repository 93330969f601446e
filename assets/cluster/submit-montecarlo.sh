#!/bin/bash
# Submits Jiang et al. 2017's Monte Carlo to Slurm as SHARDS array tasks (montecarlo.slurm) and one merge
# (montecarlo-merge.slurm) that runs once every shard succeeded and is cancelled if one fails.
#
#   RUNS=5000 assets/cluster/submit-montecarlo.sh SHARDS [sbatch options for both jobs...]
#   RUNS=5000 assets/cluster/submit-montecarlo.sh 8 --partition=batch --time=02:00:00 --cpus-per-task=4
#
# Run it from a directory that every node sees (the jobs run there). It creates OUT (default mc) before
# Slurm opens the logs in it, refuses an OUT that already holds shard files, and prints
# "ARRAY_JOB_ID MERGE_JOB_ID" on stdout (what it submitted, in words, on stderr).
# Environment: RUNS, OUT, RINSCOPE, MC_ARGS as in montecarlo.slurm; sbatch's own SBATCH_* variables work too.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
usage="usage: RUNS=N $0 SHARDS [sbatch options...]"
shards=${1:?$usage}
shift
if ! [[ $shards =~ ^[1-9][0-9]*$ ]]; then
  echo "$0: SHARDS must be a positive integer, not '$shards'" >&2
  echo "$usage" >&2
  exit 2
fi
export RUNS=${RUNS:-500}
OUT=${OUT:-mc}
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
export OUT
shopt -s nullglob
stale=("$OUT"/shard-*.json "$OUT"/all.jso[n])
if ((${#stale[@]} > 0)); then
  echo "$0: $OUT already holds ${stale[*]##*/} from an earlier run; remove them or set OUT to another folder" >&2
  exit 2
fi
array=$(sbatch --parsable --array="0-$((shards - 1))" --output="$OUT/slurm-%A_%a.log" "$@" "$here/montecarlo.slurm")
array=${array%%;*} # "id;cluster" on a multi-cluster setup
if ! merge=$(sbatch --parsable --dependency="afterok:$array" --kill-on-invalid-dep=yes --output="$OUT/merge-%j.log" "$@" "$here/montecarlo-merge.slurm"); then
  echo "$0: the merge was not submitted; cancelling array job $array" >&2
  scancel "$array" || true
  exit 1
fi
merge=${merge%%;*}
echo "rinscope-mc: array job $array: $shards shards of $RUNS runs -> $OUT/shard-K.json (logs $OUT/slurm-${array}_K.log)" >&2
echo "rinscope-mc: merge job $merge after all shards succeed -> $OUT/all.json (log $OUT/merge-$merge.log)" >&2
echo "$array $merge"
