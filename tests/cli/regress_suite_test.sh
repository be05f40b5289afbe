#!/usr/bin/env bash
# The controller-regression gate on the shipped suite: every scenario under scenarios/ matches its
# baseline in scenarios/baselines/ (exotwin regress exits 0). After an intended change of behaviour,
# re-record with `exotwin regress --update` and commit the baselines. Args: path of exotwin, source dir.
set -euo pipefail
EXO=$1
SRC=$2
T=$(mktemp -d "${TMPDIR:-/tmp}"/exotwin_regress_suite_XXXXXX)
trap 'rm -rf "$T"' EXIT
"$EXO" regress --suite "$SRC/scenarios" --out "$T"
