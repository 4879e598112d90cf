# SPDX-License-Identifier: Apache-2.0
# Scene files of many plants: the command's bytes, and its errors.
import json
import os
import shutil
import subprocess

import numpy as np
import pytest

import cambium

from conftest import SOURCE


@pytest.fixture
def field(tmp_path, monkeypatch):
    folder = tmp_path / "field"
    shutil.copytree(SOURCE / "scenes" / "field", folder)
    monkeypatch.chdir(folder)
    return folder


def test_a_scene_renders_as_the_command_writes_it(field, command):
    subprocess.run([command, "-q", "field.json", "-w", "64", "48", "--spp", "2", "-o",
                    "cmd.png"], check=True)
    scene = cambium.load_scene("field.json")
    scene.render(width=64, height=48, spp=2).write("py.png")
    assert (field / "py.png").read_bytes() == (field / "cmd.png").read_bytes()


def test_a_scene_error_is_a_cambium_error(field):
    text = (field / "field.json").read_text()
    (field / "field.json").write_text(text.replace("{", "{ ,", 1))
    with pytest.raises(cambium.Error) as caught:
        cambium.load_scene("field.json")
    assert caught.value.file.endswith("field.json")
    assert caught.value.line == 1


def test_a_scenes_exports_and_light_report_are_the_commands(field, command):
    scene = cambium.load_scene("field.json")
    for name in ("field.glb", "field.ply"):
        subprocess.run([command, "-q", "field.json", "-o", "cmd-" + name], check=True)
        scene.export("py-" + name)
        cmd = (field / ("cmd-" + name)).read_bytes()
        assert len(cmd) > 1000 and (field / ("py-" + name)).read_bytes() == cmd, name
    subprocess.run([command, "-q", "field.json", "--light-report", "cmd.json",
                    "--light-rays", "20000"], check=True)
    report = scene.light_report(light_rays=20000)
    assert report == json.loads((field / "cmd.json").read_text())
    plants = {organ["plant"] for organ in report["organs"]}
    assert len(plants) > 100  # each placement's organs, not one plant's
    with pytest.raises(cambium.Error, match="images come from render"):
        scene.export("field.png")


def test_a_scenes_turntable_is_the_commands_frames(field, command):
    subprocess.run([command, "-q", "field.json", "-w", "48", "36", "--spp", "2", "--turntable",
                    "3", "--turntable-elevation", "25", "-o", "cmd%02d.png"], check=True)
    scene = cambium.load_scene("field.json")
    stages = []
    seq = scene.turntable(3, elevation=25, width=48, height=36, spp=2,
                          progress=lambda stage, image: stages.append(stage))
    assert stages == ["assemble", "render", "frame", "frame", "frame"]
    assert seq.write("py%02d.png") == [f"py{k:02d}.png" for k in range(1, 4)]
    for k in range(1, 4):
        cmd = (field / f"cmd{k:02d}.png").read_bytes()
        assert (field / f"py{k:02d}.png").read_bytes() == cmd, k
    assert np.asarray(seq[2]).shape == (36, 48, 4)
    assert not np.array_equal(np.asarray(seq[0]), np.asarray(seq[1]))  # the field turns
    assert seq._repr_html_().count("data:image/png;base64,") == 3


def test_a_scenes_sequence_errors(field):
    scene = cambium.load_scene("field.json")
    with pytest.raises(cambium.Error, match="Scene.turntable"):
        scene.render(turntable=3)
    with pytest.raises(cambium.Error, match="light-report measures a still"):
        scene.turntable(3, light_report="light.json")
    with pytest.raises(cambium.Error, match="two kinds of sequence"):
        scene.turntable(3, animate=True)
    with pytest.raises(cambium.Error, match="keyword 'video'"):
        scene.turntable(3, video=True)
    assert not list(field.glob("*.mp4")) and not (field / "light.json").exists()


def test_one_models_options_are_refused_with_a_scene_as_by_the_command(field, command):
    for keywords, flags in [({"colormap": "plant.map"}, ["-m", "plant.map"]),
                            ({"materials": "plant.mat"}, ["-M", "plant.mat"]),
                            ({"animate": True}, ["-a"])]:
        run = subprocess.run([command, "-q", *flags, "field.json", "-o", "cmd.png"],
                             capture_output=True, text=True)
        assert run.returncode != 0
        message = run.stderr.strip().removeprefix("cambium: error: ")
        with pytest.raises(cambium.Error) as caught:
            cambium.load_scene("field.json", **keywords)
        assert message and str(caught.value).endswith(message)
    assert not (field / "cmd.png").exists()
