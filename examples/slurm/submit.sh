#!/usr/bin/env bash
# Submits a geosens run as N shards (a Slurm job array) and their merge (a
# job that starts once every shard has succeeded):
#
#   N=16 PATHS=1000000000 SCENE=scenes/fog.toml examples/slurm/submit.sh
#
# CPUS (default 1) is each shard's CPUs (--cpus-per-task, and its threads).
# Run again with the same settings after a shard failed: only the shards
# whose states are missing from STATES are submitted, then the merge (a
# merge whose shards failed is cancelled, not left waiting). The jobs run in
# the current directory (paths are relative to it); the variables of
# shards.sbatch and merge.sbatch pass through (--export=ALL).
set -euo pipefail
here=$(dirname "$0")
GEOSENS=${GEOSENS:-geosens}
STATES=${STATES:-states}
N=${N:-8}
CPUS=${CPUS:-1}
export SHARDS=$N

# A task asking for more CPUs than any node has would wait forever.
most=$(sinfo --noheader --format=%c 2>/dev/null | tr -d '+' | sort -n | tail -n 1 || true)
if [[ $most =~ ^[0-9]+$ ]] && ((CPUS > most)); then
  echo "error: CPUS=$CPUS, but no node of this cluster has more than $most CPUs" >&2
  exit 1
fi

# The shards to run: those whose states are missing (all of them at
# first); `geosens merge --missing` refuses a folder holding another run.
shopt -s nullglob
# ANCHOR: submit
missing=$("$GEOSENS" merge --missing --shards "$N" "$STATES"/shard-*.json)
deps=()
if [[ -n $missing ]]; then
  array=$(sbatch --parsable --export=ALL --cpus-per-task="$CPUS" --array="$missing" \
    "$here/shards.sbatch")
  deps=(--dependency="afterok:${array%%;*}" --kill-on-invalid-dep=yes)
fi
sbatch --export=ALL "${deps[@]}" "$here/merge.sbatch"
# ANCHOR_END: submit
