#!/usr/bin/env bash
# cmake --install of the build tree as it is (nothing rebuilt) into a temporary prefix: the layout of
# cmake/install.cmake, no source path in the installed programs, a shipped scenario run from an
# unrelated working directory, the data folder overridden by EXOTWIN_DATA_DIR and reported when
# missing (exit 2), an --out without write access (exit 2 naming it). Args: build dir, source dir, build type.
set -euo pipefail
BUILD=$1
SRC=$2
BUILD_TYPE=${3:-Release}
. "$(dirname "$0")/install_lib.sh"
T=$(mktemp -d "${TMPDIR:-/tmp}"/exotwin_install_XXXXXX)
trap 'rm -rf "$T"' EXIT
T=$(realpath "$T")
P=$T/prefix

cmake --install "$BUILD" --prefix "$P" >"$T/install.log" || { cat "$T/install.log"; fail "cmake --install"; }
echo "ok: cmake --install $BUILD --prefix $P ($(grep -c 'Installing:' "$T/install.log") files)"
for f in bin/exotwin lib/exotwin/libexotwin_controller.so share/exotwin/mjcf/leg_exowheel.xml \
         share/exotwin/data/WinterTableA1.txt share/exotwin/scenarios/gait_2kmh.yaml \
         share/exotwin/scenarios/baselines/gait_2kmh.json share/exotwin/examples/S1.yaml; do
  [ -e "$P/$f" ] || fail "$P/$f not installed"
done
for d in mjcf data scenarios examples; do
  [ ! -L "$P/share/exotwin/$d" ] || fail "$P/share/exotwin/$d is a link (expected the files)"
done
echo "ok: layout bin/, lib/exotwin/, share/exotwin/{mjcf,data,scenarios (+ baselines),examples}"

no_source_path "$P" "$SRC" "$(realpath "$BUILD")" "$BUILD_TYPE"
run_shipped "$P" "$T/a"
run_python "$P" "$T/a" "$BUILD"

# EXOTWIN_DATA_DIR overrides the program's location; a missing data folder is exit 2 naming it.
mv "$P/share/exotwin" "$T/data_elsewhere"
rc=0
(cd "$T" && env -u EXOTWIN_DATA_DIR "$P/bin/exotwin" run "$T/data_elsewhere/scenarios/faults/sensor_stuck.yaml" \
   --out "$T/b" >"$T/b.log" 2>&1) || rc=$?
[ $rc -eq 2 ] || { cat "$T/b.log"; fail "missing data folder: exit $rc, expected 2"; }
grep -q "looked for $P/share/exotwin" "$T/b.log" || { cat "$T/b.log"; fail "the message does not name $P/share/exotwin"; }
echo "ok: data folder missing: exit 2, $(grep -o 'looked for [^ ]*' "$T/b.log")"
rc=0
(cd "$T" && EXOTWIN_DATA_DIR="$T/data_elsewhere" "$P/bin/exotwin" run \
   "$T/data_elsewhere/scenarios/faults/sensor_stuck.yaml" --out "$T/c" >"$T/c.log" 2>&1) || rc=$?
[ $rc -eq 0 ] || { cat "$T/c.log"; fail "EXOTWIN_DATA_DIR=$T/data_elsewhere: exit $rc, expected 0"; }
echo "ok: EXOTWIN_DATA_DIR=$T/data_elsewhere: exit 0"
mv "$T/data_elsewhere" "$P/share/exotwin"

# An output folder without write access: exit 2 naming it. As root (write access everywhere) the
# program runs as nobody, which cannot write into the root-owned $T/ro.
mkdir "$T/ro"
if [ "$(id -u)" -eq 0 ]; then
  chmod 755 "$T"
  AS=(setpriv --reuid=65534 --regid=65534 --clear-groups)
else
  chmod 555 "$T/ro"
  AS=()
fi
if "${AS[@]}" test -x "$P/bin/exotwin"; then
  rc=0
  (cd / && "${AS[@]}" env -u EXOTWIN_DATA_DIR "$P/bin/exotwin" run "$P/share/exotwin/scenarios/faults/sensor_stuck.yaml" \
     --out "$T/ro/out" >"$T/d.log" 2>&1) || rc=$?
  [ $rc -eq 2 ] || { cat "$T/d.log"; fail "--out without write access: exit $rc, expected 2"; }
  grep -q -F "$T/ro/out" "$T/d.log" || { cat "$T/d.log"; fail "the message does not name $T/ro/out"; }
  echo "ok: --out without write access: exit 2, $(cat "$T/d.log")"
else
  echo "skipped: --out without write access (user nobody cannot reach $P/bin/exotwin: a parent folder is not searchable)"
fi
chmod -R u+w "$T"
echo "ok: install test"
