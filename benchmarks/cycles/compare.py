#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Cambium against Cycles at equal noise, one plant at a time (Blender 3.4 is a measuring
tool here, not a dependency of Cambium; see README.md beside this file):

    benchmarks/cycles/compare.py --plant WeepingBirch [--plant ...] [--size 160x120]
        [--reference-spp 1024] [--rounds 2] [--threads 2] [--build build] [--blender blender]

Per round and plant: exports the plant's scene (build/benchmarks/convergence
--export-scene), runs Cycles' convergence (cycles_convergence.py in Blender: its noise
and times at 64 spp), then Cambium's (build/benchmarks/convergence --sampler sobol
--target <Cycles' 64-spp noise>), and prints one JSON line with the ratios:

  cpu_ratio   Cambium's CPU time (user + sys) to reach Cycles' 64-spp noise / Cycles'
              CPU time for its 64 spp, both without their set-up (Cambium's BVH build
              and lights, Cycles' scene sync): the robust figure on a loaded machine.
  cpu_ratio_with_setup  the same with each renderer's set-up counted once (Cycles'
              sync: its 1-spp sync render less its 1-spp render).
  wall_ratio  the same as cpu_ratio in wall time.

Below 1: Cambium is faster. The rounds interleave the two renderers; the last line is
each plant's median ratios over the rounds. Both renderers cache their references
(build/convergence-cache/, build/cycles/cache/), so only the first round renders them.

--staged env | env-without-view-lights | sky | sky-without-view-lights: the plant staged
(convergence --stage) on a ground of albedo 0.2 (`--ground`, the plane at the plant's
lowest point), seen in perspective (`--perspective --fit --orbit 30 10`; with `--azimuth
A`, `--orbit A 10`: a turntable's frame is a still from another azimuth), lit by the
lat-long map sky_map.py writes (`--env`, seen behind the plant: `--background env`), with
the view file's lights kept or dropped (`--no-view-lights`). Noise is then measured apart on the plant's pixels
and the ground's; the JSON adds the noise at 16 and 64 spp of both renderers on both, and
`ground_cpu_ratio` / `ground_wall_ratio`: Cambium's time to Cycles' 64-spp ground noise.
The sky stagings light it with Cambium's `--sky` instead (seen behind it: `--background
sky`); Cycles' own skies are other models, so the scene export hands it this sky's dome
(and ground) as a 1024 x 512 lat-long map and its sun as a sun lamp of the same solid
angle and radiance (scene_export.h, write_sky_dome_map).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

# A ground of albedo 0.2: --ground takes a display (sRGB) value.
GROUND_AND_CAMERA = "--ground 0.4845,0.4845,0.4845 --perspective --fit --orbit {azimuth:g} 10 "
STAGE = GROUND_AND_CAMERA + "--env {map} --background env"
SKY = GROUND_AND_CAMERA + "--sky --background sky"
STAGINGS = {"env": STAGE, "env-without-view-lights": STAGE + " --no-view-lights",
            "sky": SKY, "sky-without-view-lights": SKY + " --no-view-lights"}

HERE = os.path.dirname(os.path.abspath(__file__))
PLANTS = ["FernLeaf", "WeepingBirch", "Lilac", "GeneralizedCylinder", "TranslucentTree"]


def system_python_env():
    """The environment without a virtualenv's or pyenv's python3 first on PATH: Debian's
    Blender sets its Python up from the python3 it finds there, and only the system's
    sees Debian's numpy."""
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep)
                                  if ".pyenv" not in p and p != os.path.dirname(sys.executable))
    for name in ("PYENV_VERSION", "VIRTUAL_ENV", "PYTHONHOME", "PYTHONPATH"):
        env.pop(name, None)
    return env


def json_lines(command):
    """The JSON objects a command prints, one per line (other lines ignored)."""
    run = subprocess.run(command, capture_output=True, text=True, env=system_python_env())
    if run.returncode != 0:
        sys.exit(f"compare.py: {' '.join(command)} failed:\n{run.stdout[-2000:]}"
                 f"{run.stderr[-2000:]}")
    return [json.loads(line) for line in run.stdout.splitlines() if line.startswith('{"plant"')]


def main():
    parser = argparse.ArgumentParser(prog="compare.py")
    parser.add_argument("--plant", action="append", choices=PLANTS)
    parser.add_argument("--size", default="160x120")
    parser.add_argument("--reference-spp", type=int, default=1024)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--build", default="build")
    parser.add_argument("--blender", default="blender")
    parser.add_argument("--no-mesh-lights", action="store_true",
                        help="Cycles does not sample emissive primitives as lights")
    parser.add_argument("--cycles-tilt", type=float, default=0.0,
                        help="turn Cycles' camera by this many radians (cycles_convergence.py)")
    parser.add_argument("--staged", choices=sorted(STAGINGS),
                        help="the plant staged on a ground under an HDR map (see the top)")
    parser.add_argument("--azimuth", type=float, default=30.0,
                        help="the staged camera's turn about the vertical, degrees: a "
                             "turntable's frames are stills from other azimuths")
    args = parser.parse_args()
    convergence = os.path.join(args.build, "benchmarks", "convergence")
    scenes = os.path.join(args.build, "cycles", "scenes")
    cache = os.path.join(args.build, "cycles", "cache")
    stage = []
    if args.staged:
        sky = os.path.abspath(os.path.join(args.build, "cycles", "staged", "sky.exr"))
        if args.staged.startswith("env") and not os.path.exists(sky):
            os.makedirs(os.path.dirname(sky), exist_ok=True)
            subprocess.run([sys.executable, os.path.join(HERE, "sky_map.py"), sky], check=True)
        stage = ["--stage", STAGINGS[args.staged].format(map=sky, azimuth=args.azimuth)]
        staging = args.staged + ("" if args.azimuth == 30 else f"-azimuth{args.azimuth:g}")
        scenes = os.path.join(args.build, "cycles", "staged", staging, "scenes")
        cache = os.path.join(args.build, "cycles", "staged", staging, "cache")
    ratios = {}
    for round_index in range(args.rounds):
        for plant in args.plant or PLANTS:
            common = ["--plant", plant, "--size", args.size, "--threads", str(args.threads),
                      *stage]
            if round_index == 0:
                json_lines([convergence, *common, "--export-scene", scenes])
            cycles = json_lines([args.blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                                 os.path.join(HERE, "cycles_convergence.py"), "--",
                                 "--scene", os.path.join(scenes, plant + ".json"),
                                 "--threads", str(args.threads), "--reference-spp",
                                 str(args.reference_spp), "--cache",
                                 os.path.join(cache, args.size)] +
                                (["--no-mesh-lights"] if args.no_mesh_lights else []) +
                                ["--tilt", str(args.cycles_tilt)])[0]
            cambium = json_lines([convergence, *common, "--sampler", "sobol",
                                  "--reference-spp", str(args.reference_spp),
                                  "--target", str(cycles["noise_at_max_spp"])] +
                                 (["--ground-target", str(cycles["ground_noise_at_max_spp"])]
                                  if args.staged else []))[0]
            result = {
                "plant": plant, "round": round_index + 1, "image": args.size,
                "threads": args.threads, "reference_spp": args.reference_spp,
                "cycles_mesh_lights": cycles["mesh_lights"], "cycles_tilt": cycles["tilt"],
                "cycles_noise_64": cycles["noise_at_max_spp"],
                "cycles_slope": cycles["slope"], "cambium_slope": cambium["slope"],
                "cambium_rmse_64": cambium["relative_rmse"][-1],
                "cambium_spp_to_target": cambium["spp_to_target"],
                "cycles_cpu_s": cycles["cpu_seconds_at_max_spp"],
                "cambium_cpu_s": cambium["time_to_target_render_cpu_s"],
                "cycles_setup_cpu_s": round(max(0.0, cycles["sync_cpu_s"] -
                                                cycles["cpu_seconds"][0]), 3),
                "cambium_setup_cpu_s": round(cambium["time_to_target_cpu_s"] -
                                             cambium["time_to_target_render_cpu_s"], 3),
                "cycles_s": cycles["seconds_at_max_spp"],
                "cambium_s": cambium["time_to_target_render_s"],
                "cycles_sync_s": cycles["sync_s"],
            }
            result["cpu_ratio"] = round(result["cambium_cpu_s"] / result["cycles_cpu_s"], 3)
            result["cpu_ratio_with_setup"] = round(
                (result["cambium_cpu_s"] + result["cambium_setup_cpu_s"]) /
                (result["cycles_cpu_s"] + result["cycles_setup_cpu_s"]), 3)
            result["wall_ratio"] = round(result["cambium_s"] / result["cycles_s"], 3)
            if args.staged:
                at16 = cycles["spp"].index(16)
                result.update({
                    "staged": args.staged, "azimuth": args.azimuth,
                    "cycles_noise_16": cycles["relative_rmse"][at16],
                    "cambium_rmse_16": cambium["relative_rmse"][at16],
                    "cycles_ground_noise_16": cycles["ground_relative_rmse"][at16],
                    "cycles_ground_noise_64": cycles["ground_noise_at_max_spp"],
                    "cambium_ground_rmse_16": cambium["ground_relative_rmse"][at16],
                    "cambium_ground_rmse_64": cambium["ground_relative_rmse"][-1],
                    "cambium_ground_spp_to_target": cambium["ground_spp_to_target"],
                    "cambium_ground_cpu_s": cambium["ground_time_to_target_render_cpu_s"],
                    "cambium_ground_s": cambium["ground_time_to_target_render_s"],
                })
                result["ground_cpu_ratio"] = round(
                    result["cambium_ground_cpu_s"] / result["cycles_cpu_s"], 3)
                result["ground_wall_ratio"] = round(
                    result["cambium_ground_s"] / result["cycles_s"], 3)
            ratios.setdefault(plant, []).append(result)
            print(json.dumps(result), flush=True)
    def median(runs, key):
        return round(statistics.median(r[key] for r in runs), 3) if key in runs[0] else None

    summary = {plant: {"cpu_ratio": round(statistics.median(r["cpu_ratio"] for r in runs), 3),
                       "ground_cpu_ratio": median(runs, "ground_cpu_ratio"),
                       "cpu_ratio_with_setup": round(statistics.median(
                           r["cpu_ratio_with_setup"] for r in runs), 3),
                       "wall_ratio": round(statistics.median(r["wall_ratio"] for r in runs), 3),
                       "rounds": len(runs)}
               for plant, runs in ratios.items()}
    print(json.dumps({"median": summary}), flush=True)


main()
