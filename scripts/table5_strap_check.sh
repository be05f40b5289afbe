#!/usr/bin/env bash
# Table 5's human side (issue 41's target: the strap named on most subjects' gait records), by hand
# (minutes; not a test): `table5` through the realistic EXOwheel and the human side, then each subject's
# gait record diagnosed by the motion fit twice: with the identified model (subject.yaml, what table5
# --diagnose --fit motion uses) and with the twin the record came from less its strap (truth.yaml
# without series_compliance). One line per subject: what each names.
#   scripts/table5_strap_check.sh [EXOTWIN] [SUBJECTS]   (defaults: build/app/exotwin, S1,...,S10)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
exe="${1:-$root/build/app/exotwin}"
subjects="${2:-S1,S2,S3,S4,S5,S6,S7,S8,S9,S10}"
work="$(mktemp -d "${TMPDIR:-/tmp}/table5_strap_check.XXXXXX")"
trap 'rm -rf "$work"' EXIT
(cd "$root" && "$exe" table5 --subjects "$subjects" --plant data/plants/exowheel_realistic.yaml \
  --plant-worn data/plants/human_side.yaml --out "$work/t5" > "$work/table5.log" 2>&1) ||
  { cat "$work/table5.log" >&2; exit 1; }
named() {
  python3 -c 'import json,sys
d=json.load(open(sys.argv[1]))
print("; ".join("%s %s %.4g" % (e["name"], e["joint"], e["value"]) for e in d["effects"]) or "nothing")' "$1"
}
printf '| subject | identified model | true twin less its strap |\n| --- | --- | --- |\n'
for s in ${subjects//,/ }; do
  dir="$work/t5/$s"
  grep -v series_compliance "$dir/truth.yaml" > "$dir/truth_less_strap.yaml"
  for m in subject truth_less_strap; do
    "$exe" diagnose --params "$dir/$m.yaml" --measured "$dir/gait/measured.csv" --fit motion \
      --out "$work/$s/$m" > /dev/null 2>&1 || { echo "$s: diagnose with $m.yaml failed" >&2; exit 1; }
  done
  printf '| %s | %s | %s |\n' "$s" "$(named "$work/$s/subject/diagnosis.json")" \
    "$(named "$work/$s/truth_less_strap/diagnosis.json")"
done
