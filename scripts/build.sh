#!/usr/bin/env bash
# Installs the Debian packages, then configures and builds the release tree in build/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset default > build-configure.log 2>&1 || { cat build-configure.log; exit 1; }
cmake --build --preset default
