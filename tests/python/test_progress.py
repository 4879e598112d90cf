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


def test_ctrl_c_stops_a_render_with_keyboard_interrupt(default_scene):
    child = subprocess.Popen([sys.executable, "-c", CHILD], stdout=subprocess.PIPE, text=True,
                             env=dict(os.environ))
    try:
        assert child.stdout.readline().strip() == "rendering"
        time.sleep(1.0)
        child.send_signal(signal.SIGINT)
        out, _ = child.communicate(timeout=60)
    finally:
        child.kill()
    assert out.startswith("interrupted"), out
    assert child.returncode == 0
