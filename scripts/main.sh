#!/usr/bin/env bash
# Set-up (Debian packages, configure, build) and the main job on its default scenario: 60 s of
# passive-mode gait training at 2 km/h of subject S1 (relaxed) in EXOwheel, with the real controller
# on the virtual CAN bus. Results in out/gait_2kmh/ (result.json, measured.csv, truth.csv).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
./build/app/exotwin run scenarios/gait_2kmh.yaml --out out/gait_2kmh
