#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs the Khronos glTF-Validator (an npm package, not a Debian one) into
# BUILD/gltf-validator for the glTF sweep (tests/conformance/gltf_sweep_test.cpp), which
# validates every corpus export with it when it is there and skips that part otherwise.
# The test command runs this before ctest. It never fails: without node or npm, or when
# the registry does not answer within the time limit, it says so in one line and the
# sweep skips the validator. The install goes to a private folder first and is moved into
# place only when whole, so an interrupted one leaves nothing the sweep would trust.
#   scripts/gltf-validator.sh BUILD
set -uo pipefail
build=${1:?usage: gltf-validator.sh BUILD}
target=$build/gltf-validator
limit=${CAMBIUM_NPM_TIMEOUT:-120}  # seconds for the whole npm install

if [ -n "${CAMBIUM_GLTF_VALIDATOR:-}" ]; then
  echo "test: glTF-Validator: CAMBIUM_GLTF_VALIDATOR=$CAMBIUM_GLTF_VALIDATOR"
  exit 0
fi
if [ -f "$target/node_modules/gltf-validator/package.json" ]; then
  echo "test: glTF-Validator: already in $target"
  exit 0
fi
for tool in npm node; do
  if ! command -v "$tool" > /dev/null 2>&1; then
    echo "test: glTF-Validator not installed ($tool not found): the glTF sweep skips it (docs/export.md)"
    exit 0
  fi
done

mkdir -p "$build"
work=$(mktemp -d "$build/gltf-validator.XXXXXX") || exit 0
trap 'rm -rf "$work"' EXIT
log=$build/gltf-validator.log
echo "test: installing the glTF-Validator into $target (npm, at most $limit s; log: $log)"
if timeout "$limit" npm install --prefix "$work" --no-audit --no-fund --no-save \
     --loglevel=error gltf-validator > "$log" 2>&1 &&
   [ -f "$work/node_modules/gltf-validator/package.json" ] &&
   rm -rf "$target" && mv "$work" "$target"; then
  echo "test: glTF-Validator installed in $target"
else
  echo "test: glTF-Validator not installed (npm failed or the registry did not answer in $limit s): the glTF sweep skips it"
fi
exit 0
