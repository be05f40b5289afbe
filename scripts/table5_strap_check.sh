#!/usr/bin/env bash
# Table 5's human side (issue 41's target: the strap named on most subjects' gait records), by hand
# (minutes; not a test): `table5` through the realistic EXOwheel and the human side, once with the
# paper's steps 3-4 and once with --knee-cuff --subject-passive (the same records: the plant and its
# draws do not depend on the identification), then each subject's gait record diagnosed by the motion
# fit with three models: the paper's identified model, the model identified with the cuff and the
# subject's passive moment (what table5 --knee-cuff --subject-passive --diagnose --fit motion uses), and
# the twin the record came from less its strap (truth.yaml without series_compliance). One line per
# subject: what each names.
#   scripts/table5_strap_check.sh [EXOTWIN] [SUBJECTS]   (defaults: build/app/exotwin, S1,...,S10)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
exe="${1:-$root/build/app/exotwin}"
subjects="${2:-S1,S2,S3,S4,S5,S6,S7,S8,S9,S10}"
work="$(mktemp -d "${TMPDIR:-/tmp}/table5_strap_check.XXXXXX")"
trap 'rm -rf "$work"' EXIT
for run in paper cuff; do
  flags=()
  [ "$run" = cuff ] && flags=(--knee-cuff --subject-passive)
  (cd "$root" && "$exe" table5 --subjects "$subjects" --plant data/plants/exowheel_realistic.yaml \
    --plant-worn data/plants/human_side.yaml "${flags[@]}" --out "$work/$run" > "$work/$run.log" 2>&1) ||
    { cat "$work/$run.log" >&2; exit 1; }
done
named() {
  python3 -c 'import json,sys
d=json.load(open(sys.argv[1]))
print("; ".join("%s %s %.4g" % (e["name"], e["joint"], e["value"]) for e in d["effects"]) or "nothing")' "$1"
}
printf '| subject | paper'"'"'s identified model | identified with the cuff and the subject'"'"'s passive moment | true twin less its strap |\n'
printf '| --- | --- | --- | --- |\n'
for s in ${subjects//,/ }; do
  grep -v series_compliance "$work/paper/$s/truth.yaml" > "$work/truth_less_strap_$s.yaml"
  models=("$work/paper/$s/subject.yaml" "$work/cuff/$s/subject.yaml" "$work/truth_less_strap_$s.yaml")
  line="| $s"
  for k in 0 1 2; do
    "$exe" diagnose --params "${models[$k]}" --measured "$work/paper/$s/gait/measured.csv" --fit motion \
      --out "$work/$s/$k" > /dev/null 2>&1 || { echo "$s: diagnose with ${models[$k]} failed" >&2; exit 1; }
    line="$line | $(named "$work/$s/$k/diagnosis.json")"
  done
  echo "$line |"
done
