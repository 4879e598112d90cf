# SPDX-License-Identifier: Apache-2.0
# Progress callbacks, and Ctrl-C stopping a render with KeyboardInterrupt.
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import cambium

from conftest import SOURCE


def test_progress_reports_stages_and_pass_images(default_scene):
    seen = []

    def progress(stage, image):
        seen.append((stage, None if image is None else np.asarray(image).shape))

    m = cambium.load("plant.l", "plant.v", materials="plant.mat", progress=progress)
    m.render(width=32, height=24, spp=32, progress=progress)
    stages = [s for s, _ in seen]
    assert stages[0] == "load"
    assert stages.index("derive") < stages.index("interpret") < stages.index("render")
    passes = [shape for s, shape in seen if s == "pass"]
    assert passes and all(shape == (24, 32, 4) for shape in passes)


def test_an_exception_in_the_callback_stops_the_render(default_scene):
    def progress(stage, image):
        if stage == "pass":
            raise RuntimeError("enough")

    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    start = time.monotonic()
    with pytest.raises(RuntimeError, match="enough"):
        m.render(width=64, height=48, spp=1 << 20, progress=progress)
    assert time.monotonic() - start < 60


CHILD = """
import sys, time, cambium
m = cambium.load("plant.l", "plant.v", materials="plant.mat")
print("rendering", flush=True)
start = time.monotonic()
try:
    m.render(width=64, height=48, spp=1 << 20)
except KeyboardInterrupt:
    print("interrupted", round(time.monotonic() - start, 1), flush=True)
"""


def interrupt_child(script, ready, wait, *args, cwd=None):
    """Runs `script` in a child Python, sends it Ctrl-C `wait` seconds after it printed the
    lines `ready`, and returns what it printed then."""
    child = subprocess.Popen([sys.executable, "-c", script, *args], stdout=subprocess.PIPE,
                             text=True, cwd=cwd, env=dict(os.environ))
    try:
        for line in ready:
            assert child.stdout.readline().strip() == line
        time.sleep(wait)
        child.send_signal(signal.SIGINT)
        out, _ = child.communicate(timeout=60)
    finally:
        child.kill()
    assert child.returncode == 0
    return out


def test_ctrl_c_stops_a_render_with_keyboard_interrupt(default_scene):
    out = interrupt_child(CHILD, ["rendering"], 1.0)
    assert out.startswith("interrupted"), out


SCENE_CHILD = """
import sys, time, cambium
scene = cambium.load_scene(sys.argv[1])
def progress(stage, image):
    print(stage, flush=True)
start = time.monotonic()
try:
    scene.turntable(3, width=64, height=48, spp=1 << 20, progress=progress)
except KeyboardInterrupt:
    print("interrupted", round(time.monotonic() - start, 1), flush=True)
"""


def test_ctrl_c_stops_a_scenes_turntable(tmp_path):
    # sent once the orbit's first frame is under way
    out = interrupt_child(SCENE_CHILD, ["assemble", "render"], 0.5,
                          str(SOURCE / "scenes" / "field" / "field.json"), cwd=tmp_path)
    assert out.startswith("interrupted"), out


def test_ctrl_c_stops_an_animations_export_between_frames(default_scene):
    # Ctrl-C as the first frame's file is reported: the frames after it are not written
    def progress(stage, image):
        if stage == "frame":
            signal.raise_signal(signal.SIGINT)

    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    with pytest.raises(KeyboardInterrupt):
        m.export("f%02d.glb", animate=True, steps=16, progress=progress)
    written = list(default_scene.glob("f*.glb"))
    assert 1 <= len(written) < 16
    assert not list(default_scene.glob(".*"))  # no temporary left behind
