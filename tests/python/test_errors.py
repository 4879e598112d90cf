# SPDX-License-Identifier: Apache-2.0
# Errors arrive as cambium.Error naming file, line and column; the module refuses what the
# command refuses, with the same words.
import subprocess

import pytest

import cambium


def test_a_syntax_error_names_file_line_and_column(default_scene):
    text = (default_scene / "plant.l").read_text()
    lines = text.splitlines()
    n = next(i for i, line in enumerate(lines) if line.startswith("A(l,w) -->"))
    lines[n] = lines[n].replace("-->", "-- >", 1)
    (default_scene / "plant.l").write_text("\n".join(lines) + "\n")
    with pytest.raises(cambium.Error) as caught:
        cambium.load("plant.l", "plant.v", materials="plant.mat")
    e = caught.value
    assert isinstance(e, Exception)
    assert e.file.endswith("plant.l")
    assert e.line == n + 1
    assert e.column and e.column > 0
    assert str(e).startswith(f"{e.file}:{e.line}:{e.column}: error:")


def test_a_bad_option_is_an_error(default_scene):
    with pytest.raises(cambium.Error, match="--spp"):
        cambium.load("plant.l", "plant.v", materials="plant.mat").render(spp=0)
    with pytest.raises(cambium.Error, match="Image.write"):
        cambium.load("plant.l", "plant.v", materials="plant.mat", o="x.png")
    with pytest.raises(cambium.Error):
        cambium.load("plant.l", "plant.v", no_such_option=3)


def test_a_missing_file_is_an_error(default_scene):
    with pytest.raises(cambium.Error, match="missing.l"):
        cambium.load("missing.l", "plant.v")


def command_error(command, *args):
    run = subprocess.run([command, "-q", *args], capture_output=True, text=True)
    assert run.returncode != 0
    return run.stderr.strip().removeprefix("cambium: ")


def test_an_include_outside_the_model_folder_is_refused_as_by_the_command(default_scene,
                                                                          command):
    (default_scene.parent / "outside.h").write_text("#define STEPS 2\n")
    text = (default_scene / "plant.l").read_text()
    (default_scene / "plant.l").write_text('#include "../outside.h"\n' + text)
    with pytest.raises(cambium.Error) as caught:
        cambium.load("plant.l", "plant.v", materials="plant.mat")
    assert str(caught.value) == command_error(command, "-M", "plant.mat", "plant.l", "plant.v")
    assert "outside.h" in str(caught.value)


def test_a_texture_outside_the_model_folder_is_refused_as_by_the_command(default_scene,
                                                                         command):
    with open(default_scene / "plant.v", "a") as v:
        v.write("texture: F: ../bark.png\n")
    with pytest.raises(cambium.Error) as caught:
        cambium.load("plant.l", "plant.v", materials="plant.mat")
    assert str(caught.value) == command_error(command, "-M", "plant.mat", "plant.l", "plant.v")
