#!/usr/bin/env bash
# Submits a geosens run as N shards (a Slurm job array) and their merge (a
# job that waits for all of them):
#
#   N=16 PATHS=1000000000 SCENE=scenes/fog.toml examples/slurm/submit.sh
#
# The jobs run in the current directory (paths are relative to it); the
# variables of shards.sbatch and merge.sbatch pass through (--export=ALL).
set -euo pipefail
here=$(dirname "$0")
# ANCHOR: submit
N=${N:-8}
array=$(sbatch --parsable --export=ALL --array="1-$N" "$here/shards.sbatch")
sbatch --export=ALL --dependency="afterok:${array%%;*}" "$here/merge.sbatch"
# ANCHOR_END: submit
