# SPDX-License-Identifier: Apache-2.0
# Turntables: the frames the command's --turntable writes, and an HTML animation.
import subprocess

import numpy as np
import pytest

import cambium


def test_turntable_frames_are_the_commands_bytes(default_scene, command):
    subprocess.run([command, "-q", "-M", "plant.mat", "-w", "48", "36", "--spp", "2",
                    "--turntable", "4", "--turntable-elevation", "20", "-o", "cmd%02d.png",
                    "plant.l", "plant.v"], check=True)
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    seq = m.turntable(4, elevation=20, width=48, height=36, spp=2)
    assert len(seq) == 4
    assert seq.write("py%02d.png") == [f"py{k:02d}.png" for k in range(1, 5)]
    for k in range(1, 5):
        assert (default_scene / f"py{k:02d}.png").read_bytes() == \
            (default_scene / f"cmd{k:02d}.png").read_bytes(), k
    # the views differ, and each frame is an image numpy reads
    assert not np.array_equal(np.asarray(seq[0]), np.asarray(seq[1]))
    assert np.asarray(seq[-1]).shape == (36, 48, 4)


def test_a_sequence_shows_as_an_html_animation(default_scene):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    seq = m.turntable(3, width=16, height=12, spp=1)
    html = seq._repr_html_()
    assert html.count("data:image/png;base64,") == 3
    assert "<script>" in html and "setInterval" in html


def test_render_refuses_a_sequence(default_scene):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    with pytest.raises(cambium.Error, match="turntable"):
        m.render(turntable=3)


def test_animation_frames_are_the_commands_bytes(default_scene, command):
    # cpfg's default frames (1 to the derivation length), with one in-between each
    subprocess.run([command, "-q", "-M", "plant.mat", "-a", "--steps", "3", "--inbetween", "1",
                    "-w", "40", "30", "--spp", "2", "-o", "cmd%02d.png", "plant.l", "plant.v"], check=True)
    made = sorted(p.name for p in default_scene.glob("cmd*.png"))
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    seq = m.animate(steps=3, inbetween=1, width=40, height=30, spp=2)
    assert len(seq) == len(made) and len(seq) > 2
    assert seq.write("py%02d.png") == [n.replace("cmd", "py") for n in made]
    for name in made:
        assert (default_scene / name.replace("cmd", "py")).read_bytes() == (default_scene / name).read_bytes(), name
    # the plant grows from frame to frame
    assert not np.array_equal(np.asarray(seq[0]), np.asarray(seq[-1]))


def test_animate_refuses_a_turntable(default_scene):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    with pytest.raises(cambium.Error, match="turntable"):
        m.animate(turntable=3)
