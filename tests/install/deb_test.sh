#!/usr/bin/env bash
# cpack -G DEB on the build tree as it is (nothing rebuilt): the package's metadata (dpkg-deb -I: name,
# architecture, the Debian dependencies dpkg-shlibdeps found) and contents (dpkg-deb -c), then the
# package extracted into a temporary root (dpkg-deb -x; nothing is installed into /usr) and a shipped
# scenario run from there. Args: build dir, source dir, build type.
set -euo pipefail
BUILD=$1
SRC=$2
BUILD_TYPE=${3:-Release}
. "$(dirname "$0")/install_lib.sh"
for tool in cpack dpkg-deb dpkg-shlibdeps; do
  command -v $tool >/dev/null || fail "$tool not found (scripts/setup.sh installs dpkg-dev and cmake)"
done
T=$(mktemp -d "${TMPDIR:-/tmp}"/exotwin_deb_XXXXXX)
trap 'rm -rf "$T"' EXIT
T=$(realpath "$T")

cpack -G DEB --config "$BUILD/CPackConfig.cmake" -B "$T/pkg" >"$T/cpack.log" 2>&1 || { cat "$T/cpack.log"; fail "cpack -G DEB"; }
debs=("$T"/pkg/*.deb)
[ ${#debs[@]} -eq 1 ] && [ -f "${debs[0]}" ] || fail "cpack made ${#debs[@]} packages: ${debs[*]}"
DEB=${debs[0]}
echo "ok: cpack -G DEB: $(basename "$DEB") ($(du -k "$DEB" | cut -f1) kB)"

dpkg-deb -I "$DEB" >"$T/info"
grep -E '^ [A-Z][A-Za-z-]*:' "$T/info"
grep -q '^ Package: exotwin$' "$T/info" || fail "package name"
grep -q "^ Architecture: $(dpkg --print-architecture)$" "$T/info" || fail "architecture"
deps=$(sed -n 's/^ Depends: //p' "$T/info")
[ -n "$deps" ] || fail "no Depends: field"
for lib in libc6 libstdc++6 libmujoco libyaml-cpp; do
  grep -q "$lib" <<<"$deps" || fail "Depends: does not name $lib ($deps)"
done
echo "ok: dpkg-deb -I: Depends: names libc6, libstdc++6, libmujoco, libyaml-cpp"
if ls "$BUILD"/lib/python3/dist-packages/exotwin/_exotwin*.so >/dev/null 2>&1; then
  grep -q '^ Recommends: .*python3-numpy' "$T/info" || fail "Recommends: does not name python3-numpy (the Python module)"
  echo "ok: dpkg-deb -I: Recommends: $(sed -n 's/^ Recommends: //p' "$T/info")"
fi

dpkg-deb -c "$DEB" | awk '{print $6}' >"$T/contents"
for f in ./usr/bin/exotwin ./usr/lib/exotwin/libexotwin_controller.so ./usr/share/exotwin/mjcf/leg_exowheel.xml \
         ./usr/share/exotwin/data/WinterTableA1.txt ./usr/share/exotwin/scenarios/faults/sensor_stuck.yaml \
         ./usr/share/exotwin/scenarios/baselines/gait_2kmh.json ./usr/share/exotwin/examples/S1.yaml; do
  grep -q -x -F "$f" "$T/contents" || fail "dpkg-deb -c: $f missing"
done
bad=$(grep -v -E '^\./(usr/?|usr/(bin|lib|share)(/.*)?)$' "$T/contents" || true)
[ -z "$bad" ] || fail "files outside /usr/{bin,lib,share}: $bad"
echo "ok: dpkg-deb -c: $(grep -c -v '/$' "$T/contents") files under /usr/bin, /usr/lib/exotwin, /usr/share/exotwin"

dpkg-deb -x "$DEB" "$T/root"
no_source_path "$T/root/usr" "$SRC" "$(realpath "$BUILD")" "$BUILD_TYPE"
run_shipped "$T/root/usr" "$T/a"
run_python "$T/root/usr" "$T/a" "$BUILD"
echo "ok: .deb test"
