#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The large-scene benchmark suite (docs/benchmarks.md): renders the 12 M-segment tree, the
# meadow and the forest once each with --stats-json, keeps the pictures, and writes the
# table between the scene-suite markers of docs/benchmarks.md with the machine it ran on.
#
# Usage: benchmarks/scenes/run.sh [--quick] [--build DIR] [--out DIR]
#   --quick   the tree at 11 of its 14 steps (about 0.45 M segments) and 4 spp: a check that
#             the suite runs, not figures to keep (the table then says "quick")
#   --build   the build folder holding src/app/cambium (default: build)
#   --out     where the images and JSON go (default: build/scene-suite)
# Not part of ctest: the full suite takes minutes and gigabytes.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
quick=0
build="$root/build"
out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1 ;;
    --build) build=$(cd "$2" && pwd); shift ;;
    --out) out="$2"; shift ;;
    *) echo "usage: $0 [--quick] [--build DIR] [--out DIR]" >&2; exit 2 ;;
  esac
  shift
done
out=${out:-$build/scene-suite}
mkdir -p "$out"
cambium="$build/src/app/cambium"
[ -x "$cambium" ] || { echo "$cambium not found: build it first (cmake --build build --target cambium)" >&2; exit 1; }

spp=8
tree_steps=()
if [ "$quick" = 1 ]; then spp=4; tree_steps=(--steps 11); fi

# Runs one scene: NAME, then cambium's arguments. A failure is recorded, not fatal, so the
# table shows what this build cannot do yet (e.g. scene files before they are supported).
run_scene() {
  local name=$1; shift
  echo "== $name: cambium $*" >&2
  rm -f "$out/$name.json"
  local status=0 TIMEFORMAT='%R %U %S'  # bash's time: wall, user and system seconds
  { time "$cambium" "$@" -o "$out/$name.png" --stats --stats-json "$out/$name.json" \
      > "$out/$name.log" 2>&1 || status=$?; } 2> "$out/$name.time"
  if [ "$status" = 0 ]; then
    echo "ok" > "$out/$name.status"
  else
    echo "failed: $(grep -m1 'cambium:' "$out/$name.log" || tail -n1 "$out/$name.log")" > "$out/$name.status"
  fi
  cat "$out/$name.status" >&2
}

tree="$here/models/tree10m"
run_scene tree10m "$tree/tree.l" "$tree/tree.v" -M "$tree/plants.mat" "${tree_steps[@]}" \
  -w 640 480 --spp "$spp"
run_scene meadow "$here/meadow.json" --spp "$spp"
run_scene forest "$here/forest.json" --spp "$spp"

python3 "$here/report.py" --out "$out" --quick "$quick" --cambium "$cambium" \
  --doc "$root/docs/benchmarks.md" --repo "$root"
echo "wrote $root/docs/benchmarks.md (images and JSON in $out)" >&2
