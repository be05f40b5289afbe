#!/usr/bin/env bash
# The short form of the command-line mutation fuzz (issue 43, tests/cli/fuzz_cli.py): a few hundred
# seeded mutations of the shipped inputs, shared among the readers, each given to the command that
# reads it; any exit but 0, 1 or 2, an "internal error", a signal or a hang fails. The long form:
#   tests/cli/fuzz_cli.py build/app/exotwin . --count 30000 --seed S
# Args: path of exotwin, source dir.
set -euo pipefail
exec python3 "$(dirname "$0")/fuzz_cli.py" "$1" "$2" --count "${FUZZ_CLI_COUNT:-330}" --seed 1 --jobs 2 --timeout 60
