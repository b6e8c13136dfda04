#!/usr/bin/env bash
# Submits a geosens run as N shards (a Slurm job array) and their merge (a
# job that waits for all of them):
#
#   N=16 PATHS=1000000000 SCENE=scenes/fog.toml ./submit.sh
#
# The variables of shards.sbatch and merge.sbatch pass through (--export=ALL).
set -euo pipefail
cd "$(dirname "$0")"
N=${N:-8}
array=$(sbatch --parsable --export=ALL --array="1-$N" shards.sbatch)
sbatch --export=ALL --dependency="afterok:${array%%;*}" merge.sbatch
