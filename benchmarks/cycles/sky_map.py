#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes the staged comparison's lighting as a latitude-longitude EXR map (deterministic,
numpy and oiiotool only; the map itself is not kept in the repository):

    benchmarks/cycles/sky_map.py OUT.exr [--width 512]

A sky gradient (blue at the zenith, pale at the horizon), a dim brown ground below the
horizon and a small bright sun (0.75 degrees in radius, 35 degrees up), as Cambium's --env
and Blender's Environment Texture read a lat-long image: column u = azimuth over a turn,
row v = polar angle from the zenith over pi, rows from the top. In Cambium's frame (+y up)
the direction at (u, v) is (-sin t sin phi, cos t, sin t cos phi), phi = 2 pi u, t = pi v
(render/environment.h, LatLongTable).
"""
import argparse
import os
import subprocess
import tempfile

import numpy as np

SUN_AZIMUTH_TURNS = 0.35      # phi / 2 pi: toward -x and -z of the plant
SUN_ELEVATION_DEG = 35.0
SUN_RADIUS_DEG = 0.75
SUN_IRRADIANCE = 3.0 * np.pi  # on a surface facing it: the view-file light of colour 3
SUN_COLOUR = np.array([1.0, 0.95, 0.85])


def lat_long(width):
    height = width // 2
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    phi, t = np.meshgrid(2 * np.pi * u, np.pi * v)
    direction = np.stack([-np.sin(t) * np.sin(phi), np.cos(t), np.sin(t) * np.cos(phi)], -1)
    up = direction[..., 1:2]
    zenith, horizon = np.array([0.25, 0.45, 0.95]), np.array([0.85, 0.9, 1.0])
    sky = horizon + (zenith - horizon) * np.sqrt(np.clip(up, 0, 1))
    ground = np.array([0.12, 0.09, 0.06]) * np.ones_like(sky)
    rgb = np.where(up > 0, sky, ground)
    sun_phi, sun_t = 2 * np.pi * SUN_AZIMUTH_TURNS, np.radians(90 - SUN_ELEVATION_DEG)
    sun = np.array([-np.sin(sun_t) * np.sin(sun_phi), np.cos(sun_t),
                    np.sin(sun_t) * np.cos(sun_phi)])
    inside = direction @ sun >= np.cos(np.radians(SUN_RADIUS_DEG))
    # Each texel's solid angle, so that the disc as drawn gives exactly SUN_IRRADIANCE.
    solid = (2 * np.pi / width) * (np.pi / height) * np.sin(t)
    cos_to_sun = np.clip(direction @ sun, 0, 1)
    radiance = SUN_IRRADIANCE / (solid * cos_to_sun)[inside].sum()
    rgb[inside] = radiance * SUN_COLOUR / SUN_COLOUR.max()
    return rgb.astype(np.float32), sun


def main():
    parser = argparse.ArgumentParser(prog="sky_map.py")
    parser.add_argument("out")
    parser.add_argument("--width", type=int, default=512)
    args = parser.parse_args()
    rgb, sun = lat_long(args.width)
    height, width = rgb.shape[:2]
    with tempfile.TemporaryDirectory() as folder:
        pfm = os.path.join(folder, "map.pfm")
        with open(pfm, "wb") as f:  # PFM: little-endian floats, rows from the bottom
            f.write(f"PF\n{width} {height}\n-1.0\n".encode())
            f.write(np.ascontiguousarray(rgb[::-1]).astype("<f4").tobytes())
        subprocess.run(["oiiotool", pfm, "-d", "float", "-o", args.out], check=True)
    print(f"{args.out}: {width}x{height}, sun toward {np.round(sun, 4).tolist()} (+y up)")


main()
