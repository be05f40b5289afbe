#!/usr/bin/env bash
# Installs the Debian packages exotwin needs (only the missing ones) and configures + builds the project.
# Usage: scripts/setup.sh [--no-build]
set -euo pipefail
cd "$(dirname "$0")/.."

PKGS=(
  build-essential cmake pkg-config
  libmujoco-dev libqhull-dev          # physics (find_package(mujoco) needs qhull's CMake config)
  libeigen3-dev                       # linear algebra
  libosmesa6-dev                      # off-screen OpenGL for render/
  libopencv-dev                       # overlays (render/); videoio decodes the videos in tests
  libavcodec-dev libavformat-dev libswscale-dev  # MP4 encoding (render/mp4_writer.cc), x264 inside
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  zlib1g-dev libzstd-dev liblz4-dev   # MCAP (formats/mcap_*): CRC-32, zstd and lz4 chunks
  lz4                                 # the reference lz4 command: lz4 chunks of the bag tests (tests/mcap_client)
  libgtest-dev libgmock-dev libbenchmark-dev
  can-utils                           # log2asc for the candump round-trip test
  clang libclang-rt-14-dev            # libFuzzer targets in fuzz/ (-DEXOTWIN_FUZZ=ON, -fsanitize=fuzzer)
  parallel                            # GNU parallel: the sweep split-and-merge test (tests/cli)
  slurm-wlm munge                     # a one-node Slurm for scripts/test_slurm.sh (the sweep job array)
  file dpkg-dev                       # cpack -G DEB: dpkg-shlibdeps computes the dependencies, `file` finds the ELF files
  python3                             # examples/python_controller (a controller from outside the project; its serve test)
  python3-dev pybind11-dev python3-numpy python3-pytest  # the Python module (python/) and its tests (tests/python)
  python3-matplotlib                  # examples/python (the plots, Agg)
)

missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The independent MCAP / ROS 2 client of the bag tests (tests/mcap_client: Foxglove's @mcap/core and
# ROS 2 serialization, pinned by its package-lock.json), from the npm registry.
# Installed again when its lock file is newer than what node_modules holds.
if command -v npm >/dev/null && { [ ! -f tests/mcap_client/node_modules/.package-lock.json ] ||
     [ tests/mcap_client/package-lock.json -nt tests/mcap_client/node_modules/.package-lock.json ]; }; then
  (cd tests/mcap_client && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
fi

if [ "${1:-}" != "--no-build" ]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build -j"$(nproc)"
  # `import exotwin` for Debian's python3 without PYTHONPATH: a .pth in its site folder naming the build
  # tree's module (cmake --install and the .deb install the module itself instead).
  if [ -d build/lib/python3/dist-packages/exotwin ] && [ -x /usr/bin/python3 ]; then
    site=$(/usr/bin/python3 -c 'import site; print(site.getsitepackages()[0])')
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO mkdir -p "$site"
    echo "$PWD/build/lib/python3/dist-packages" | $SUDO tee "$site/exotwin-build-tree.pth" >/dev/null
  fi
fi
