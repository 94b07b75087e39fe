#!/usr/bin/env bash
# The main job: installs deps, builds, and generates a small data set with the distributed service on this machine
# (drapegen local: a coordinator plus one worker per core, the embedded default run of coarse meshes), then prints
# the manifest's statistics. Output: out/local-run/ (manifest.sqlite, data/*.ply, data/*.exr); a previous demo run
# there is replaced.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
rm -rf out/local-run
build/bin/drapegen local --workers "$(nproc)" --output out/local-run "$@"
