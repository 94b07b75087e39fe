#!/usr/bin/env bash
# Configures and builds drapegen in ./build (Release). Extra arguments go to cmake's configure step.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" > build.log 2>&1 || { cat build.log; exit 1; }
ninja -C build >> build.log 2>&1 || { tail -50 build.log; exit 1; }
echo "build: ok (build/bin/drapegen)"
