#!/usr/bin/env bash
# Installs what valo needs, builds it (build/valo) and renders the bundled default scene
# to default.png (and default.exr). Extra arguments go to `valo render`.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
build/valo render scenes/default.json -o default.png -o default.exr "$@"
