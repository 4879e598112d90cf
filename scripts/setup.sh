#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs the Debian packages Cambium needs that are missing (idempotent).
# `scripts/setup.sh --list` prints the list instead; scripts/check-packages.sh (a ctest)
# fails when the build or the tests read a file from a package that is not in it.
set -euo pipefail

# Every Debian (bookworm) package the build, the tests and the benchmarks use, in one place.
# Packages these pull in through a hard Depends need no line; Recommends are never installed.
packages=(
  # tools: build, test runner, and the C preprocessor cambium runs on .l files
  cmake make g++ cpp
  # libraries of the renderer and the command
  libembree-dev libtbb-dev libcli11-dev libfmt-dev nlohmann-json3-dev
  libopenimageio-dev libopenexr-dev
  # glTF exports (.glb): tinygltf (MIT) writes them, the tests read them back
  libtinygltf-dev
  # @L labels: FreeType draws the glyphs, fontconfig finds a font for cpfg's font names,
  # DejaVu is the font it finds on a bare system
  libfreetype-dev libfontconfig-dev fonts-dejavu-core
  # OpenImageIO's CMake package requires its command-line tools (iconvert, oiiotool, ...)
  # to exist; Debian has them only as a Recommends of libopenimageio-dev.
  openimageio-tools
  # -ps, .svg and .pdf outputs: cairo (LGPL-2.1/MPL-1.1, linked dynamically) draws them
  libcairo2-dev
  # tests and benchmarks
  libgtest-dev libbenchmark-dev
  # zlib: the conformance tests read cpfg's gzipped rayshade exports (scene.ray.gz)
  zlib1g-dev
  # the scene files' JSON Schema (docs/scene.schema.json) is checked in the suite
  python3-jsonschema
  # Open MPI (BSD licence) for --mpi: the module libcambium_mpi.so links it, the tests
  # run mpirun (docs/distributed.md)
  libopenmpi-dev openmpi-bin
  # the Python module (docs/python.md): pybind11 and the Python headers build it, numpy
  # reads its images, pytest runs its tests; nbconvert and the IPython kernel execute the
  # example notebook (examples/python/plants.ipynb) in the suite
  pybind11-dev python3-dev python3-numpy python3-pytest
  jupyter-nbconvert python3-ipykernel
)
# Not installed on purpose: python3-imath. Imath's CMake package names its Python binding,
# which Cambium does not use (CMakeLists.txt keeps the resulting notice quiet).
# Optional for developers: clang-format (.clang-format), ccache.

if [ "${1:-}" = "--list" ]; then
  printf '%s\n' "${packages[@]}"
  exit 0
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} Debian packages are installed"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
echo "setup: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
