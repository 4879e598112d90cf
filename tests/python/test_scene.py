# SPDX-License-Identifier: Apache-2.0
# Scene files of many plants: the command's bytes, and its errors.
import os
import shutil
import subprocess

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
