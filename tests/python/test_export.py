# SPDX-License-Identifier: Apache-2.0
# Geometry exports from Python: the same files as the command's -o, -ray and -iv.
import subprocess

import pytest

import cambium


def test_exports_are_the_commands_files(default_scene, command):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    for name in ("plant.obj", "plant.ply", "plant.glb", "plant.svg", "plant.ray", "plant.iv"):
        option = {".ray": "-ray", ".iv": "-iv"}.get(name[name.rfind("."):], "-o")
        subprocess.run([command, "-q", "-M", "plant.mat", option, "cmd-" + name,
                        "plant.l", "plant.v"], check=True)
        m.export("py-" + name)
        cmd = (default_scene / ("cmd-" + name)).read_bytes()
        py = (default_scene / ("py-" + name)).read_bytes()
        if name.endswith(".obj"):  # its mtllib line names its own MTL file
            cmd, py = cmd.replace(b"cmd-plant.mtl", b""), py.replace(b"py-plant.mtl", b"")
        if name.endswith(".ray"):  # the main object is named after the file
            cmd, py = cmd.replace(b"cmd-plant.ray", b""), py.replace(b"py-plant.ray", b"")
        assert len(py) > 1000 and py == cmd, name


def test_an_edited_string_is_exported(default_scene):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    s = m.derive()
    m.export("whole.obj", string=s)
    for i in s.find("L"):  # no leaves
        s.parameters[s.offsets[i]] = 0
    m.export("bare.obj", string=s)
    assert (default_scene / "bare.obj").read_bytes() != (default_scene / "whole.obj").read_bytes()


def test_what_export_cannot_write_is_an_error(default_scene):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    with pytest.raises(cambium.Error, match="images come from render"):
        m.export("plant.png")
    with pytest.raises(cambium.Error, match="not with -a or --turntable"):
        m.export("plant%d.obj", turntable=4)
    assert not (default_scene / "plant.png").exists()
