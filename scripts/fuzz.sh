#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Fuzzes Cambium's readers with libFuzzer (docs/security.md):
#   scripts/fuzz.sh [TARGET|all] [MINUTES]      (default: all, 5 minutes per target)
# Builds the targets in build-fuzz/ with clang++ (apt-get install clang), collects seed
# inputs from the corpus (../shared/corpus or $CAMBIUM_CORPUS) into build-fuzz/seeds/,
# and runs each target for MINUTES in one process that goes on after a crash. New
# inputs are kept in build-fuzz/corpus/TARGET (the next run starts from them); crashes,
# timeouts and out-of-memory inputs land in build-fuzz/crashes/TARGET/. Reproduce one
# with: build-fuzz/fuzz/TARGET_fuzz FILE
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

targets=(lsystem view_file surface tsurface contour function curve background string_text string_binary animation
         scene_file obj_mesh tile label env_map comm_spec spec)
target=${1:-all}
minutes=${2:-5}
build=${FUZZ_BUILD:-build-fuzz}
corpus=${CAMBIUM_CORPUS:-$root/../shared/corpus}

if [ "$target" != all ] && [[ ! " ${targets[*]} " =~ " $target " ]]; then
  echo "usage: scripts/fuzz.sh [all|${targets[*]// /|}] [minutes]" >&2
  exit 2
fi
if ! command -v clang++ >/dev/null; then
  echo "fuzz: needs clang++ and libFuzzer: apt-get install clang" >&2
  exit 2
fi

echo "fuzz: building the targets in $build"
cmake -S . -B "$build" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCAMBIUM_FUZZ=ON -DCAMBIUM_BUILD_TESTS=OFF -DCAMBIUM_BUILD_BENCHMARKS=OFF > "$build.configure.log" 2>&1 ||
  { cat "$build.configure.log"; exit 1; }
cmake --build "$build" --target fuzz --parallel "${JOBS:-2}"

# Seeds: the corpus's files of each format (up to the targets' 64 KiB input limit),
# plus the hand-written ones in fuzz/seeds/ for formats the corpus lacks.
corpus_files() {  # corpus_files NAME-PATTERN...: files under the corpus, <= 64 KiB
  local args=() p
  for p in "$@"; do args+=(-o -name "$p"); done
  [ -d "$corpus" ] && find "$corpus" -type f -size -65k \( "${args[@]:1}" \) | sort
}
seed() {  # seed TARGET: fills $build/seeds/TARGET
  local dir=$build/seeds/$1 files=()
  rm -rf "$dir"
  mkdir -p "$dir"
  local f
  for f in fuzz/seeds/"$1"/*; do
    if [ -f "$f" ]; then cp "$f" "$dir"/; fi
  done
  case $1 in
    lsystem)       mapfile -t files < <(corpus_files '*.l')
                   [ ${#files[@]} -gt 0 ] && "$build/fuzz/cambium_fuzz_seed" lsystem "$dir" "${files[@]}" ;;
    string_binary) mapfile -t files < <(corpus_files '*.str')
                   [ ${#files[@]} -gt 0 ] && "$build/fuzz/cambium_fuzz_seed" strb "$dir" "${files[@]}" ;;
    *)
      case $1 in
        view_file)   mapfile -t files < <(corpus_files '*.v') ;;
        surface)     mapfile -t files < <(corpus_files '*.s') ;;
        tsurface)    mapfile -t files < <(corpus_files '*.ray' '*.tri') ;;
        contour)     mapfile -t files < <(corpus_files '*.con' '*.cset') ;;
        function)    mapfile -t files < <(corpus_files '*.func' '*.fset') ;;
        curve)       mapfile -t files < <(corpus_files '*.crv' '*.con') ;;
        background)  mapfile -t files < <(corpus_files '*.dat') ;;
        string_text) mapfile -t files < <(corpus_files '*.str') ;;
        animation)   mapfile -t files < <(corpus_files '*.a') ;;
        scene_file)  mapfile -t files < <(find scenes -name '*.json' | sort) ;;
        obj_mesh)    mapfile -t files < <(corpus_files '*.obj') ;;
        comm_spec)   mapfile -t files < <(corpus_files '*.e') ;;
        spec)        mapfile -t files < <(corpus_files '*.spec') ;;
      esac
      local i=0
      for f in "${files[@]}"; do cp "$f" "$dir/corpus$((i++))"; done ;;
  esac
  echo "fuzz: $1: $(ls "$dir" | wc -l) seeds"
}

run() {  # run TARGET: fuzzes it for $minutes
  local t=$1
  seed "$t"
  mkdir -p "$build/corpus/$t" "$build/crashes/$t" "$build/work/$t"
  local dict=()
  [ -f "fuzz/$t.dict" ] && dict=(-dict="$root/fuzz/$t.dict")
  echo "fuzz: $t for $minutes min (crashes in $build/crashes/$t/)"
  # Run in a scratch folder: an L-system may open files relative to it (fopen).
  # -fork=1: one worker that is restarted after a crash, a timeout or an out-of-memory
  # input, so one finding does not end the run. Limits: 64 KiB inputs, 10 s and 2 GB each.
  (cd "$build/work/$t" &&
    ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1} \
    "$root/$build/fuzz/${t}_fuzz" "$root/$build/corpus/$t" "$root/$build/seeds/$t" "${dict[@]}" \
      -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
      -max_total_time=$((minutes * 60)) -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$root/$build/crashes/$t/" -print_final_stats=1 \
      > "$root/$build/crashes/$t.log" 2>&1) || true
  tail -n 3 "$build/crashes/$t.log"
  local found
  found=$(find "$build/crashes/$t" -type f | wc -l)
  echo "fuzz: $t: $found input(s) in $build/crashes/$t/ (log: $build/crashes/$t.log)"
}

if [ "$target" = all ]; then
  for t in "${targets[@]}"; do run "$t"; done
else
  run "$target"
fi
