#!/usr/bin/env bash
# The 5-fold cross-validation of docs/SAMPLER.md ("Cross-validation"): the folds one after another (one process, one
# thread each, niced: the machine is shared), then the pooled summary and the energy-distance floor. Any further
# arguments go to every run, the summary and the floor included (e.g. --check-every 10000 --dir DIR for the
# final-epoch variant; --folds N runs N folds).
# About 25 minutes on the 2-core development machine (shared).
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=/usr/bin/python3
T=training/vae
DIR=$T/results/crossval
FOLDS=5
args=("$@")
for ((i = 0; i < ${#args[@]}; ++i)); do
  case ${args[i]} in
    --dir) DIR=${args[i + 1]} ;;
    --dir=*) DIR=${args[i]#--dir=} ;;
    --folds) FOLDS=${args[i + 1]} ;;
    --folds=*) FOLDS=${args[i]#--folds=} ;;
  esac
done
mkdir -p "$DIR"
: > "$DIR/wall.txt"
for ((fold = 0; fold < FOLDS; ++fold)); do
  start=$(date +%s)
  nice -n 15 $PY $T/crossval.py --fold $fold --threads 1 "$@" 2> "$DIR/log_fold_$fold.txt"
  echo "fold $fold rc 0 wall $(( $(date +%s) - start )) s" >> "$DIR/wall.txt"
done
# The same arguments (--folds, --data, --seed, --generated ...) for the summary and the floor as for the folds.
$PY $T/crossval.py --summarise --dir "$DIR" "$@" | tee "$DIR/summary.txt"
$PY $T/crossval.py --floor --dir "$DIR" "$@" | tee "$DIR/energy_floor.txt"
