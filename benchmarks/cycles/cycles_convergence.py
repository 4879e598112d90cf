# SPDX-License-Identifier: Apache-2.0
"""Cycles' side of the convergence benchmark, run inside Blender 3.4 (a measuring tool,
not part of Cambium):

    blender -b --factory-startup --python benchmarks/cycles/cycles_convergence.py -- \\
        --scene build/cycles/scenes/WeepingBirch.json [--threads 2] [--max-spp 64] \\
        [--reference-spp 1024] [--cache build/cycles/cache]

builds the exported scene (import_scene.py), renders it once at 1 spp to sync it (scene
export, BVH build, shader compilation: reported as `sync_s`, kept out of the render
times by Cycles' persistent data), renders or reuses a high-spp reference (another
seed, cached as EXR), then renders at 1, 2, 4, ... max spp and prints one JSON line
(starting with {"plant") with each render's relative RMSE against the reference,
computed as benchmarks/convergence does for Cambium: sqrt(mean over plant pixels and RGB
of (value - reference)^2) / mean(reference), over the view's background, plant pixels
being those whose reference alpha is at least 0.5; its wall and CPU seconds (the process's user + sys); the slope
of log RMSE against log spp; and the noise and times at the highest spp. A staged scene
(convergence --stage) is measured on the plant's pixels and, apart, on the ground's
(`ground_relative_rmse`, ...), the pixels its export wrote beside it (SCENE.region).
"""
import argparse
import json
import math
import os
import sys
import time

import bpy
import numpy as np
from mathutils import Matrix

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import import_scene  # noqa: E402  (needs the folder on the path first)


def cpu_seconds():
    t = os.times()
    return t.user + t.system


def timed_render(path, spp, seed):
    wall, cpu = time.perf_counter(), cpu_seconds()
    import_scene.render_exr(path, spp, seed)
    return time.perf_counter() - wall, cpu_seconds() - cpu


def over_background(rgba, background):
    """The transparent film's premultiplied pixels over the view's background: the
    pixels an opaque film gives (camera rays that miss see the background, as in
    Cambium's images), with the coverage kept in alpha for the plant mask."""
    out = rgba.astype(np.float64)
    out[:, :3] += (1 - out[:, 3:4]) * np.asarray(background, dtype=np.float64)
    return out


def relative_rmse(image, reference, pixels=None):
    plant = reference[:, 3] >= 0.5 if pixels is None else pixels
    diff = image[plant, :3] - reference[plant, :3]
    mean = reference[plant, :3].mean()
    return float(math.sqrt((diff * diff).mean()) / mean) if mean > 0 else 0.0


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="cycles_convergence.py")
    parser.add_argument("--scene", required=True, help="a convergence --export-scene file")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--max-spp", type=int, default=64)
    parser.add_argument("--reference-spp", type=int, default=1024)
    parser.add_argument("--cache", default="build/cycles/cache")
    parser.add_argument("--no-mesh-lights", action="store_true",
                        help="emissive primitives are not sampled as lights")
    parser.add_argument("--tilt", type=float, default=0.0,
                        help="turn the camera by this many radians about its right and up "
                             "axes: camera rays without exactly zero components (Embree's "
                             "round curves are very slow on those; Cambium nudges them)")
    parser.add_argument("--render-only", type=int, metavar="SPP",
                        help="after the sync, render once at SPP and print its times only "
                             "(no reference, no noise): a window to profile Cycles' render "
                             "in, e.g. its share of time inside Embree under perf")
    args = parser.parse_args(argv)

    plant = os.path.splitext(os.path.basename(args.scene))[0]
    wall, cpu = time.perf_counter(), cpu_seconds()
    scene = import_scene.build_scene(args.scene, args.threads, not args.no_mesh_lights)
    if args.tilt:
        camera = bpy.context.scene.camera
        right, up = camera.matrix_world.col[0].xyz, camera.matrix_world.col[1].xyz
        turn = Matrix.Rotation(args.tilt, 4, right) @ Matrix.Rotation(args.tilt, 4, up)
        location = camera.matrix_world.translation.copy()
        camera.matrix_world = Matrix.Translation(location) @ turn @ \
            Matrix.Translation(-location) @ camera.matrix_world
    import_seconds = (time.perf_counter() - wall, cpu_seconds() - cpu)
    os.makedirs(args.cache, exist_ok=True)
    # The reference is cached per setting that changes how Cycles samples (its noise
    # adds to every measured error): the camera tilt and whether emitters are lights.
    size = f"{scene['width']}x{scene['height']}" + (f"-tilt{args.tilt:g}" if args.tilt else "") + \
        ("-no-mesh-lights" if args.no_mesh_lights else "")
    scratch = os.path.join(args.cache, f"{plant}-{size}-run.exr")
    sync = timed_render(scratch, 1, 0)
    if args.render_only:
        start = time.clock_gettime(time.CLOCK_MONOTONIC)
        w, c = timed_render(scratch, args.render_only, 0)
        end = time.clock_gettime(time.CLOCK_MONOTONIC)
        print(json.dumps({"plant": plant, "renderer": "cycles", "image": size,
                          "threads": args.threads, "spp": args.render_only,
                          "seconds": round(w, 3), "cpu_seconds": round(c, 3),
                          "sync_s": round(sync[0], 3), "window_s": [start, end]}), flush=True)
        return

    reference_file = os.path.join(args.cache, f"{plant}-{size}-{args.reference_spp}.exr")
    reference_seconds = None
    if not os.path.exists(reference_file):
        reference_seconds = timed_render(reference_file, args.reference_spp, 0x5eed)
    background = scene["background"]
    reference = over_background(import_scene.read_exr(reference_file), background)
    plant_pixels, ground_pixels = None, None
    if "stage" in scene:
        # A staged scene's pixels of the plant (1) and of the ground (2), as Cambium's
        # export measured them (rows from the top; Blender's from the bottom).
        region = np.fromfile(os.path.splitext(args.scene)[0] + ".region", dtype=np.uint8)
        region = region.reshape(scene["height"], scene["width"])[::-1].ravel()
        plant_pixels, ground_pixels = region == 1, region == 2

    spps, rmse, ground_rmse, seconds, cpu_s = [], [], [], [], []
    spp = 1
    while spp <= args.max_spp:
        w, c = timed_render(scratch, spp, 0)
        spps.append(spp)
        image = over_background(import_scene.read_exr(scratch), background)
        rmse.append(relative_rmse(image, reference, plant_pixels))
        if ground_pixels is not None:
            ground_rmse.append(relative_rmse(image, reference, ground_pixels))
        seconds.append(w)
        cpu_s.append(c)
        spp *= 2
    x, y = np.log(spps), np.log(rmse)
    slope = float(np.polyfit(x, y, 1)[0])
    result = {
        "plant": plant, "renderer": "cycles", "image": size, "threads": args.threads,
        "reference_spp": args.reference_spp, "mesh_lights": not args.no_mesh_lights,
        "tilt": args.tilt,
        "spp": spps,
        "relative_rmse": [round(r, 5) for r in rmse],
        "seconds": [round(s, 3) for s in seconds], "cpu_seconds": [round(s, 3) for s in cpu_s],
        "slope": round(slope, 3), "noise_at_max_spp": round(rmse[-1], 5),
        "seconds_at_max_spp": round(seconds[-1], 3),
        "cpu_seconds_at_max_spp": round(cpu_s[-1], 3),
        "samples_per_s": round(scene["width"] * scene["height"] * sum(spps) / sum(seconds)),
        "import_s": round(import_seconds[0], 3),
        "sync_s": round(sync[0], 3), "sync_cpu_s": round(sync[1], 3),
        "reference_s": round(reference_seconds[0], 3) if reference_seconds else None,
    }
    if ground_rmse:
        result["ground_relative_rmse"] = [round(r, 5) for r in ground_rmse]
        result["ground_slope"] = round(float(np.polyfit(x, np.log(ground_rmse), 1)[0]), 3)
        result["ground_noise_at_max_spp"] = round(ground_rmse[-1], 5)
    print(json.dumps(result), flush=True)


main()
