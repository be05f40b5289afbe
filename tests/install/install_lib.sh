# Shared by tests/install/*_test.sh (sourced): checks on an installed tree.

fail() { echo "FAIL: $*"; exit 1; }

# no_source_path ROOT SRC BUILD TYPE: no program or library under ROOT (bin/, lib/) holds the source
# path or the build path (RPATH included). TYPE: the build type; debug information and assertions
# name the source files, so the check is for the release builds.
no_source_path() {
  local root=$1 src=$2 build=$3 type=$4 f p n=0
  case "$type" in
    Release|MinSizeRel) ;;
    *) echo "skipped: source path check (a $type build names its source files in debug information or assertions)"; return 0 ;;
  esac
  for f in "$root"/bin/* "$root"/lib/exotwin/* "$root"/lib/python3/dist-packages/exotwin/*.so; do
    [ -f "$f" ] || continue
    n=$((n + 1))
    for p in "$src" "$build"; do
      if grep -q -a -F "$p" "$f"; then
        strings -a "$f" | grep -F "$p" | head -5
        fail "$f holds the path $p"
      fi
    done
  done
  [ $n -gt 0 ] || fail "no program under $root/bin"
  echo "ok: none of the $n programs and libraries under $root holds the source path $src or the build path $build"
}

# run_shipped ROOT WORK: runs a shipped scenario with ROOT/bin/exotwin from an unrelated working
# directory (WORK/cwd), the data found next to the program; checks its result.json.
run_shipped() {
  local root=$1 work=$2 rc=0
  mkdir -p "$work/cwd"
  (cd "$work/cwd" && env -u EXOTWIN_DATA_DIR "$root/bin/exotwin" run \
     "$root/share/exotwin/scenarios/faults/sensor_stuck.yaml" --out "$work/run" >"$work/run.log" 2>&1) || rc=$?
  [ $rc -eq 0 ] || { cat "$work/run.log"; fail "exotwin run from $work/cwd: exit $rc, expected 0"; }
  local r="$work/run/result.json"
  [ -f "$r" ] || fail "no $r"
  grep -q '"scenario": "fault_sensor_stuck"' "$r" || fail "$r does not name the scenario"
  grep -q '"passed": true' "$r" || fail "$r has no passed check"
  ! grep -q '"passed": false' "$r" || fail "$r has a failed check"
  [ -f "$work/run/measured.csv" ] || [ -n "$(ls "$work"/run/*.csv 2>/dev/null)" ] || fail "the run wrote no CSV log"
  [ -z "$(ls -A "$work/cwd")" ] || fail "the run wrote into its working directory: $(ls -A "$work/cwd")"
  echo "ok: $root/bin/exotwin run (cwd $work/cwd): exit 0, $(grep -c '"passed": true' "$r") checks passed"
}

# run_python ROOT WORK BUILD: when BUILD built the Python module (python/CMakeLists.txt), checks that
# ROOT holds it (ROOT/lib/python3/dist-packages/exotwin) and that Debian's python3 imports it from an
# unrelated working directory, the data found next to the package, and runs a shipped scenario.
run_python() {
  local root=$1 work=$2 build=$3 rc=0 py=/usr/bin/python3
  if ! ls "$build"/lib/python3/dist-packages/exotwin/_exotwin*.so >/dev/null 2>&1; then
    echo "skipped: the Python module (not built in $build)"
    return 0
  fi
  ls "$root"/lib/python3/dist-packages/exotwin/_exotwin*.so >/dev/null 2>&1 || fail "$root/lib/python3/dist-packages/exotwin/_exotwin*.so not installed"
  [ -f "$root/lib/python3/dist-packages/exotwin/__init__.py" ] || fail "$root/lib/python3/dist-packages/exotwin/__init__.py not installed"
  mkdir -p "$work/pycwd"
  (cd "$work/pycwd" && env -u EXOTWIN_DATA_DIR PYTHONPATH="$root/lib/python3/dist-packages" PYTHONDONTWRITEBYTECODE=1 "$py" -c "
import exotwin, sys
r = exotwin.run('$root/share/exotwin/scenarios/faults/sensor_stuck.yaml')
assert r.scenario == 'fault_sensor_stuck' and len(r.measured['t']) > 0, r
print('rows', len(r.measured['t']), 'passed', r.passed, 'from', exotwin.__file__)
" >"$work/py.log" 2>&1) || rc=$?
  [ $rc -eq 0 ] || { cat "$work/py.log"; fail "$py: import exotwin; exotwin.run from $work/pycwd: exit $rc"; }
  grep -q "from $root/lib/python3/dist-packages/exotwin/__init__.py" "$work/py.log" || { cat "$work/py.log"; fail "the module imported is not $root's"; }
  echo "ok: $py imports exotwin from $root/lib/python3/dist-packages and runs a shipped scenario: $(cat "$work/py.log")"
}
