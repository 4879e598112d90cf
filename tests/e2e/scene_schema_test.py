#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""docs/scene.schema.json checked against the project's scenes and against the parser.

1. The schema is a valid JSON Schema (draft 2020-12).
2. Every scene file in scenes/ and benchmarks/scenes/ validates against it.
3. Good scenes, one per feature the schema describes, validate and cambium accepts them.
4. Bad scenes that cambium rejects (a clear error naming the JSON path, no output file)
   are rejected by the schema too: the rules it can express. Rules it cannot (files that
   must exist, distinct eye and look_at, non-zero directions, scatter rectangles with
   min < max) are listed apart and checked on the parser's side only.

Usage: scene_schema_test.py SOURCE_DIR CAMBIUM_EXE. Exits 77 (skipped) without the
jsonschema module (Debian: python3-jsonschema).
"""
import copy
import json
import os
import re
import subprocess
import sys
import tempfile

try:
    import jsonschema
except ImportError:
    print("skipped: the Python module jsonschema is not installed (apt-get install python3-jsonschema)")
    sys.exit(77)

failures = []


def fail(message):
    failures.append(message)
    print("FAIL:", message)


def strip_comments(text):
    """cambium's // and /* */ comments, outside strings, as the scene parser allows them."""
    return re.sub(r'"(?:\\.|[^"\\])*"|//[^\n]*|/\*.*?\*/',
                  lambda m: m.group(0) if m.group(0).startswith('"') else "", text, flags=re.S)


def scene_files(source):
    for folder in ("scenes", os.path.join("benchmarks", "scenes")):
        for root, _, files in os.walk(os.path.join(source, folder)):
            for name in sorted(files):
                if name.endswith(".json"):
                    path = os.path.join(root, name)
                    with open(path) as f:
                        doc = json.loads(strip_comments(f.read()))
                    if isinstance(doc, dict) and "plants" in doc:  # not model.json files
                        yield path, doc


PLANT_L = "lsystem: 1\nderivation length: 1\naxiom: F\nendlsystem\n"
PLANT_V = "line style: cylinder\ninitial line width: 0.2\n"

BASE = {
    "plants": [{"model": "m", "command": "cpfg p.l p.v", "placements": [{"translate": [0, 0, 0]}]}]
}


def scene(**changes):
    """BASE with top-level keys replaced; a value None removes the key."""
    doc = copy.deepcopy(BASE)
    for key, value in changes.items():
        if value is None:
            doc.pop(key, None)
        else:
            doc[key] = value
    return doc


def plant(**changes):
    p = copy.deepcopy(BASE["plants"][0])
    for key, value in changes.items():
        if value is None:
            p.pop(key, None)
        else:
            p[key] = value
    return scene(plants=[p])


def scatter(**keys):
    s = {"rectangle": [-5, -5, 5, 5], "count": 3}
    s.update(keys)
    return plant(placements={"scatter": {k: v for k, v in s.items() if v is not None}})


GOOD = {
    "minimal": scene(),
    "every_top_level_key": scene(
        ground={"size": [10, 10], "colour": "#6b5a3c", "texture_repeat": 2},
        camera={"eye": [0, 2, 10], "look_at": [0, 1, 0], "up": [0, 1, 0], "fov_deg": 40,
                "projection": "perspective", "width": 16, "height": 12},
        lights=[{"type": "directional", "direction": [0.4, 1, 0.6], "colour": [1, 0.9, 0.8],
                 "intensity": 1},
                {"type": "point", "position": [0, 5, 0], "colour": "#ffffff"}],
        sky={"sun": [0.4, 1, 0.6], "turbidity": 3},
        render={"spp": 1, "max_depth": 4, "seed": 3, "noise_target": 0.05, "time_budget_s": 10,
                "exposure": 0.5, "ambient": 0.1, "filter": "gaussian", "tonemap": "filmic",
                "background": "#203040"}),
    "steps_and_seed": plant(steps=[1, 2], seed=7),
    "single_step": plant(steps=0),
    "matrix_placement": plant(placements=[{"matrix": [1, 0, 0, 0, 1, 0, 0, 0, 1, 3, 0, 0]},
                                          {"translate": [1, 0, 1], "rotate_y_deg": 30, "scale": 2}]),
    "scatter_rectangle": scatter(seed=4, min_spacing=0.5, rotate_y=True, scale=[0.8, 1.2]),
    "parallel_camera": scene(camera={"projection": "parallel"}),
    "colour_block_option": plant(command="cpfg -c1 p.l p.v -w 100 100"),
    "meshes_only": scene(plants=None, meshes=[{"file": "p.obj", "placements": [{}]}]),
    "plants_and_meshes": scene(meshes=[{"file": "p.obj",
                                        "placements": {"scatter": {"rectangle": [-5, -5, 5, 5],
                                                                   "count": 2}}}]),
}

# name: (document, words the parser's error holds: the JSON path and the reason)
BAD = {
    "unknown_top_level_key": (scene(colour=1), "colour: unknown key"),
    "no_plants": (scene(plants=None), "needs a plants list"),
    "empty_plants": (scene(plants=[]), "plants: must be a non-empty list"),
    "plant_without_command": (plant(command=None), "plants[0]: needs a command"),
    "command_not_cpfg": (plant(command="gcc p.l"), "plants[0].command: must start with 'cpfg'"),
    "unknown_plant_key": (plant(colour=2), "plants[0].colour: unknown key"),
    "negative_seed": (plant(seed=-1), "plants[0].seed"),
    "repeated_steps": (plant(steps=[2, 2]), "plants[0].steps"),
    "steps_not_integers": (plant(steps="3"), "plants[0].steps"),
    "placements_not_a_list": (plant(placements=5), "plants[0].placements"),
    "matrix_and_translate": (plant(placements=[{"matrix": [1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0],
                                                "translate": [0, 0, 0]}]),
                             "plants[0].placements[0]"),
    "matrix_of_11": (plant(placements=[{"matrix": [1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0]}]),
                     "plants[0].placements[0].matrix"),
    "translate_of_2": (plant(placements=[{"translate": [0, 0]}]),
                       "plants[0].placements[0].translate"),
    "zero_scale": (plant(placements=[{"scale": 0}]), "plants[0].placements[0].scale"),
    "scatter_count_zero": (scatter(count=0), "plants[0].placements.scatter.count"),
    "scatter_without_count": (scatter(count=None), "plants[0].placements.scatter: needs a count"),
    "scatter_rectangle_and_mesh": (scatter(mesh="g.obj"), "plants[0].placements.scatter"),
    "scatter_neither_rectangle_nor_mesh": (scatter(rectangle=None), "plants[0].placements.scatter"),
    "scatter_scale_of_one": (scatter(scale=[1]), "plants[0].placements.scatter.scale"),
    "ground_size_and_mesh": (scene(ground={"size": [1, 1], "mesh": "g.obj"}), "ground"),
    "ground_colour_and_texture": (scene(ground={"size": [1, 1], "colour": "#000000",
                                                "texture": "t.png"}), "ground"),
    "ground_colour_short": (scene(ground={"size": [1, 1], "colour": "#12345"}), "ground.colour"),
    "ground_colour_above_one": (scene(ground={"size": [1, 1], "colour": [2, 0, 0]}),
                                "ground.colour"),
    "camera_projection": (scene(camera={"projection": "fisheye"}), "camera.projection"),
    "camera_width_zero": (scene(camera={"width": 0}), "camera.width"),
    "camera_fov_180": (scene(camera={"fov_deg": 180}), "camera.fov_deg"),
    "light_type": (scene(lights=[{"type": "spot", "position": [0, 1, 0]}]), "lights[0].type"),
    "too_many_lights": (scene(lights=[{"type": "directional", "direction": [0, 1, 0]}] * 65),
                        "lights"),
    "sky_and_environment": (scene(sky={}, environment={"map": "e.hdr"}), "sky or environment"),
    "sky_turbidity": (scene(sky={"turbidity": 20}), "sky.turbidity"),
    "environment_without_map": (scene(environment={"scale": 1}), "environment"),
    "render_spp_zero": (scene(render={"spp": 0}), "render.spp"),
    "render_filter": (scene(render={"filter": "lanczos"}), "render.filter"),
    "render_tonemap": (scene(render={"tonemap": "aces"}), "render.tonemap"),
    "render_unknown_key": (scene(render={"samples": 4}), "render.samples: unknown key"),
    "mesh_without_file": (scene(meshes=[{"placements": [{}]}]), "meshes[0]: needs a file"),
    "mesh_unknown_key": (scene(meshes=[{"file": "p.obj", "placements": [{}], "colour": 1}]),
                         "meshes[0].colour: unknown key"),
    "empty_meshes": (scene(meshes=[]), "meshes: must be a non-empty list"),
}

# Rejected by the parser; beyond what the schema can say (files, geometry of values).
PARSER_ONLY = {
    "model_not_a_folder": (plant(model="missing"), "plants[0].model"),
    "model_outside_folder": (plant(model="../elsewhere"), "plants[0].model"),
    "rectangle_inverted": (scatter(rectangle=[5, -5, -5, 5]), "plants[0].placements.scatter.rectangle"),
    "eye_equals_look_at": (scene(camera={"eye": [0, 1, 0], "look_at": [0, 1, 0]}), "camera.look_at"),
    "directional_light_zero": (scene(lights=[{"type": "directional", "direction": [0, 0, 0]}]),
                               "lights[0].direction"),
    "command_writes_files": (plant(command="cpfg -str out.str p.l p.v"), "plants[0].command"),
    "mesh_not_a_file": (scene(meshes=[{"file": "missing.obj", "placements": [{}]}]),
                        "meshes[0].file"),
    "mesh_bad_index": (scene(meshes=[{"file": "bad.obj", "placements": [{}]}]),
                       "bad.obj:4:"),
}


def run_cambium(cambium, folder, doc, name):
    """cambium on `doc` with -vv only (assembles the scene, renders nothing)."""
    path = os.path.join(folder, name + ".json")
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
    vv = os.path.join(folder, name + ".vv")
    result = subprocess.run([cambium, path, "-vv", vv, "-q"], capture_output=True, text=True,
                            timeout=120)
    return result.returncode, result.stderr, os.path.exists(vv)


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    source, cambium = sys.argv[1], sys.argv[2]
    with open(os.path.join(source, "docs", "scene.schema.json")) as f:
        schema = json.load(f)
    validator_class = jsonschema.validators.validator_for(schema)
    validator_class.check_schema(schema)
    validator = validator_class(schema)

    examples = list(scene_files(source))
    if len(examples) < 3:
        fail(f"expected the example scenes (field, meadow, forest); found {len(examples)}")
    for path, doc in examples:
        errors = sorted(validator.iter_errors(doc), key=lambda e: list(e.path))
        for e in errors:
            fail(f"{os.path.relpath(path, source)}: {'/'.join(map(str, e.path))}: {e.message}")
    print(f"{len(examples)} example scenes checked")

    with tempfile.TemporaryDirectory() as folder:
        os.mkdir(os.path.join(folder, "m"))
        with open(os.path.join(folder, "m", "p.l"), "w") as f:
            f.write(PLANT_L)
        with open(os.path.join(folder, "m", "p.v"), "w") as f:
            f.write(PLANT_V)
        with open(os.path.join(folder, "p.obj"), "w") as f:
            f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
        with open(os.path.join(folder, "bad.obj"), "w") as f:
            f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 5\n")
        for name, doc in GOOD.items():
            errors = list(validator.iter_errors(doc))
            if errors:
                fail(f"good scene {name}: the schema rejects it: {errors[0].message}")
            status, stderr, wrote = run_cambium(cambium, folder, doc, "good_" + name)
            if status != 0 or not wrote:
                fail(f"good scene {name}: cambium rejects it: {stderr.strip()}")
        for table, schema_rejects in ((BAD, True), (PARSER_ONLY, False)):
            for name, (doc, words) in table.items():
                status, stderr, wrote = run_cambium(cambium, folder, doc, "bad_" + name)
                if status == 0 or wrote:
                    fail(f"bad scene {name}: cambium accepts it")
                elif f"bad_{name}.json: " not in stderr or words not in stderr:
                    fail(f"bad scene {name}: cambium's error does not name the file and "
                         f"'{words}': {stderr.strip()}")
                rejected = not validator.is_valid(doc)
                if schema_rejects and not rejected:
                    fail(f"bad scene {name}: the schema accepts what cambium rejects")
    print(f"{len(GOOD)} good and {len(BAD)} + {len(PARSER_ONLY)} bad scenes checked")
    if failures:
        print(f"{len(failures)} failure(s)")
        return 1
    print("the schema agrees with the parser")
    return 0


if __name__ == "__main__":
    sys.exit(main())
