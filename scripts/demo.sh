#!/usr/bin/env bash
# The main job until the distributed generation run exists: simulate one drape of a median fabric from
# ../shared/data/fabrics618.csv on the drape tester and print its summary.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
mkdir -p out
build/bin/drapegen simulate --alpha 13923,11455,8821 --beta=-35390,-29660,-22042 --density 300 \
  --init sine --seed 1 --drift 2 --out out/drape.ply "$@"
