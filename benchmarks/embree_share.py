#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The share of a render's CPU samples spent inside Embree, for Cambium and for Cycles
alike: how much of a path tracer's time is ray traversal and how much its own work.

    perf record -k CLOCK_MONOTONIC -F 4000 -o P.data \\
        build/benchmarks/convergence --raw-embree-only --size 320x240 --plant P > P.json
    perf script -i P.data -F time,ip,sym,dso | benchmarks/embree_share.py P.json

The JSON file is the benchmark's output: its last line with a `trace_window_s`
(Cambium's timed render, benchmarks/convergence.cpp) or a `window_s` (Cycles' render,
`cycles_convergence.py --render-only SPP`) gives the span, on CLOCK_MONOTONIC, to count
samples in (perf must record with `-k CLOCK_MONOTONIC`). Prints one JSON line: the
samples in the window, the percentage in Embree's library, per library, and the
busiest symbols outside Embree.
"""
import collections
import json
import re
import sys

SAMPLE = re.compile(r"\s*(\d+\.\d+):\s+[0-9a-f]+\s+(.*?)\s*\(([^()]*)\)\s*$")


def window(json_path):
    span = None
    with open(json_path) as f:
        for line in f:
            line = line.strip()
            if not line.startswith("{"):
                continue
            record = json.loads(line)
            span = record.get("trace_window_s") or record.get("window_s") or span
    if not span:
        sys.exit(f"{json_path}: no line with trace_window_s or window_s")
    return span


def library(path):
    name = path.rsplit("/", 1)[-1]
    return "embree" if "libembree" in name else name


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: perf script -F time,ip,sym,dso | embree_share.py BENCHMARK.json")
    start, end = window(sys.argv[1])
    libraries, symbols = collections.Counter(), collections.Counter()
    for line in sys.stdin:
        m = SAMPLE.match(line)
        if not m or not start <= float(m.group(1)) <= end:
            continue
        lib = library(m.group(3))
        libraries[lib] += 1
        if lib != "embree":
            symbols[m.group(2)[:80] or "[unknown]"] += 1
    n = sum(libraries.values())
    if n == 0:
        sys.exit("no samples in the window: was perf run with -k CLOCK_MONOTONIC?")
    share = lambda c: round(100.0 * c / n, 1)  # noqa: E731
    print(json.dumps({
        "window_s": round(end - start, 3), "samples": n,
        "embree_percent": share(libraries["embree"]),
        "libraries_percent": {k: share(v) for k, v in libraries.most_common(6)},
        "top_outside_embree_percent": {k: share(v) for k, v in symbols.most_common(8)},
    }))


main()
