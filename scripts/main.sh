#!/usr/bin/env bash
# Set-up (Debian packages, configure, build) and the main job on its default input.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
mkdir -p out
./build/app/exotwin predict --params examples/S1.yaml --measured examples/S1_excitation.csv \
  --out out/S1_excitation_pred.csv
echo "wrote out/S1_excitation_pred.csv"
