#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes the scene-suite section of docs/benchmarks.md from run.sh's --stats-json files."""
import argparse
import datetime
import json
import os
import pathlib
import platform
import subprocess

BEGIN = "<!-- scene-suite:begin (benchmarks/scenes/run.sh writes this section) -->"
END = "<!-- scene-suite:end -->"

SCENES = [
    ("tree10m", "A single tree of about 12 M segments", "models/tree10m/tree.l"),
    ("meadow", "A meadow of 10 500 herbs (grass, clover, daisies)", "meadow.json"),
    ("forest", "A forest of 1 100 trees of five species with leaves", "forest.json"),
]


def machine(cambium, repo):
    cpu = "unknown CPU"
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    mem_kb = 0
    with open("/proc/meminfo") as f:
        for line in f:
            if line.startswith("MemTotal:"):
                mem_kb = int(line.split()[1])
    commit = subprocess.run(["git", "-C", repo, "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "-C", repo, "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()
    load = os.getloadavg()
    return (f"{cpu}, {os.cpu_count()} cores, {mem_kb / 2**20:.1f} GiB RAM, "
            f"{platform.system()} {platform.release()}; "
            f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC; "
            f"commit {commit}{' (with local changes)' if dirty else ''}; "
            f"load average at the end {load[0]:.1f} (other work shares the machine)")


def mib(b):
    return f"{b / 2**20:,.1f} MiB"


def table(stats, wall, cpu, target_first_pixel=None, target_peak=None):
    t = stats["times_s"]
    p = stats["primitives"]
    placed = stats["placed_primitives"]
    m = stats["memory_bytes"]
    per = stats["bytes_per_primitive"]
    r = stats["render"]
    rows = [
        ("time to first pixel", f"{t['first_pixel']:.2f} s" if t["first_pixel"] is not None else "-",
         target_first_pixel),
        ("&nbsp;&nbsp;load / derive / interpret (together) / build",
         f"{t['load']:.2f} / {t['derive']:.2f} / {t['interpret']:.2f} ({t['assemble']:.2f}) / "
         f"{t['build']:.2f} s", None),
        ("rendering (after the first pixel)", f"{t['render']:.2f} s", None),
        ("whole command: wall, CPU (user + system)", f"{wall:.2f} s, {cpu:.2f} s", None),
        ("primitives built", f"{p['total']:,} ({p['cylinders']:,} cylinders, "
                             f"{p.get('lines', 0):,} pixel-width lines, {p['curve_segments']:,} "
                             f"curve segments, {p['spheres']:,} spheres, {p['discs']:,} discs, "
                             f"{p['triangles']:,} triangles)", None),
        ("instances (prototypes)", f"{stats['instances']:,} ({stats['prototypes']:,})", None),
        ("primitives placed", f"{placed['total']:,}", None),
        ("Embree memory (peak)", f"{mib(m['embree'])} ({mib(m['embree_peak'])})", None),
        ("&nbsp;&nbsp;and its instance geometries, unseen by its memory monitor",
         mib(m.get('embree_unmonitored', 0)), None),
        ("Cambium memory: Scene buffers + renderer's (of it read by Embree in place)",
         f"{mib(m.get('scene_buffers', m['cambium']))} + {mib(m.get('render_buffers', 0))} "
         f"({mib(m.get('embree_shared', 0))})", None),
        ("peak process memory", mib(m["peak_process"]), target_peak),
        ("bytes per primitive: Embree / Cambium / process peak",
         f"{per['embree']:.1f} / {per['cambium']:.1f} / {per['peak_process']:.1f}", None),
        ("memory per primitive ÷ what Embree needs, (Embree + Cambium) / (Embree + read in place)",
         f"{per['ratio_to_embree']:.2f}×", "< 1.2×"),
        ("(the same, Embree's memory as its monitor reports it alone)",
         f"{per.get('ratio_to_embree_monitor', per['ratio_to_embree']):.2f}×", None),
        ("(the earlier measure, (Embree + Cambium) / Embree's allocations)",
         f"{per.get('ratio_to_embree_allocations', 0):.2f}×", None),
        ("image, samples", f"{r['width']}×{r['height']}, {r['samples']:,} samples", None),
        ("samples/s", f"{r['samples_per_s']:,.0f}", None),
        ("rays/s", f"{r['rays_per_s']:,.0f}", None),
    ]
    lines = ["| figure | measured | target |", "|---|---|---|"]
    for name, value, target in rows:
        lines.append(f"| {name} | {value} | {target or ''} |")
    return "\n".join(lines)


def main():
    a = argparse.ArgumentParser()
    a.add_argument("--out", required=True)
    a.add_argument("--quick", default="0")
    a.add_argument("--cambium", required=True)
    a.add_argument("--doc", required=True)
    a.add_argument("--repo", required=True)
    args = a.parse_args()
    out = pathlib.Path(args.out)
    parts = [BEGIN, "", "## Large plant scenes", "",
             "Written by `benchmarks/scenes/run.sh`" + (" --quick (the tree at 11 of 14 steps, 4 spp: "
             "not figures to keep)" if args.quick == "1" else "") + " on: " +
             machine(args.cambium, args.repo) + ".", "",
             "Times are wall seconds from `--stats-json`; time to first pixel counts from the start "
             "of `main`. For scene files, load, derive and interpret are summed over the threads "
             "that assemble the plants in parallel; \"together\" is their wall time. "
             "Images and JSON: `" + str(out) + "`.", ""]
    targets = {"tree10m": ("< 15 s", None), "forest": (None, "< 2 GB")}
    for name, title, source in SCENES:
        parts += [f"### {name}: {title}", "", f"`benchmarks/scenes/{source}`", ""]
        status = (out / f"{name}.status").read_text().strip() if (out / f"{name}.status").exists() else "not run"
        stats_file = out / f"{name}.json"
        if status != "ok" or not stats_file.exists():
            parts += [f"Not measured: {status}", ""]
            continue
        stats = json.loads(stats_file.read_text())
        wall, user, system = (float(v) for v in (out / f"{name}.time").read_text().split())
        first_pixel, peak = targets.get(name, (None, None))
        parts += [table(stats, wall, user + system, first_pixel, peak), ""]
    parts.append(END)
    section = "\n".join(parts)

    doc = pathlib.Path(args.doc)
    text = doc.read_text() if doc.exists() else "# Benchmarks\n\n"
    if BEGIN in text and END in text:
        text = text[:text.index(BEGIN)] + section + text[text.index(END) + len(END):]
    else:
        text = text.rstrip("\n") + "\n\n" + section + "\n"
    doc.write_text(text)


if __name__ == "__main__":
    main()
