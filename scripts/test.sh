#!/usr/bin/env bash
# Set-up (Debian packages, configure, build) and the whole test suite. Used by .ci/run.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 900
