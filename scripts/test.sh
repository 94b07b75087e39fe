#!/usr/bin/env bash
# Installs dependencies, builds, and runs the test suite (all tests without the "bench" label).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
ctest --test-dir build --output-on-failure --label-exclude bench -j "$(nproc)"
