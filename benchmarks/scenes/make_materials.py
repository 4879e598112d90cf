#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes plants.mat, the cpfg material file every benchmark plant uses (-M plants.mat),
into each model folder under models/. A record is 15 bytes (manual 5.4.2): index,
transparency, ambient RGB, diffuse RGB, emission RGB, specular RGB, shininess.
Run it again after changing the table; the .mat files are committed."""
import pathlib

# index: (name, diffuse RGB, specular RGB, shininess); ambient is a fifth of the diffuse.
MATERIALS = {
    0: ("background", (0, 0, 0), (0, 0, 0), 0),
    1: ("bark", (92, 70, 52), (10, 10, 10), 4),
    2: ("branch", (108, 84, 60), (10, 10, 10), 4),
    3: ("twig", (120, 98, 66), (10, 10, 10), 4),
    4: ("green shoot", (78, 112, 44), (20, 20, 20), 8),
    5: ("leaf", (62, 118, 40), (40, 40, 40), 20),
    6: ("light leaf", (118, 156, 52), (40, 40, 40), 20),
    7: ("needles", (34, 78, 44), (30, 30, 30), 16),
    8: ("petal", (236, 234, 224), (30, 30, 30), 10),
    9: ("flower centre", (232, 188, 36), (30, 30, 30), 10),
    10: ("grass", (84, 140, 48), (30, 30, 30), 16),
    11: ("birch bark", (206, 200, 188), (20, 20, 20), 6),
    12: ("autumn leaf", (190, 84, 30), (40, 40, 40), 20),
}
BACKGROUND_EMISSION = (170, 198, 226)  # cpfg: material 0's emission is the background


def record(index, diffuse, specular, shininess):
    ambient = tuple(c // 5 for c in diffuse)
    emission = BACKGROUND_EMISSION if index == 0 else (0, 0, 0)
    return bytes([index, 0, *ambient, *diffuse, *emission, *specular, shininess])


def main():
    data = b"".join(record(i, d, s, n) for i, (_, d, s, n) in sorted(MATERIALS.items()))
    here = pathlib.Path(__file__).resolve().parent
    for folder in sorted((here / "models").iterdir()):
        if folder.is_dir():
            (folder / "plants.mat").write_bytes(data)


if __name__ == "__main__":
    main()
