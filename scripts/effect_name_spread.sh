#!/usr/bin/env bash
# How many non-test source files hold each effect family's name as a string literal (issue 62's
# measure of "one home per effect"): one line per family, then the median and the maximum.
#   scripts/effect_name_spread.sh [--files]
set -euo pipefail
cd "$(dirname "$0")/.."
names=$(sed -n 's/^| `\([a-z_]*\)` | [^|]* | .*/\1/p' DESIGN.md | awk '!seen[$0]++' | head -13)
counts=()
for n in $names; do
  files=$(grep -rl "\"$n\"" --include=*.cc --include=*.h --include=*.py \
            core model dsp protocol controller deploy sim hwsim formats identification diagnosis emg render \
            runner batch app python bench examples 2>/dev/null | sort)
  c=$(echo -n "$files" | grep -c . || true)
  counts+=("$c")
  if [ "${1:-}" = --files ]; then echo "$n $c: $(echo $files)"; else echo "$n $c"; fi
done
printf '%s\n' "${counts[@]}" | sort -n | awk '{a[NR]=$1} END {print "median " a[int((NR+1)/2)] ", max " a[NR]}'
