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
    with pytest.raises(cambium.Error, match="a turntable turns one geometry"):
        m.export("plant%d.obj", turntable=4)
    with pytest.raises(cambium.Error, match="names one file for 3 frames"):
        m.export("plant.glb", animate=True, steps=3)
    with pytest.raises(cambium.Error, match="each frame's string"):
        m.export("plant%d.glb", animate=True, string=m.derive())
    assert not list(default_scene.glob("plant*.png")) and not list(default_scene.glob("plant*.glb"))


def test_an_animations_geometry_is_a_file_per_frame(default_scene, command):
    # the command's -a -o with a number field: a file per frame, named by its step
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    for pattern in ("f%02d.glb", "f%02d.ply", "f%02d.ray"):
        option = "-ray" if pattern.endswith(".ray") else "-o"
        subprocess.run([command, "-q", "-M", "plant.mat", "-a", "--steps", "3", option,
                        "cmd-" + pattern, "plant.l", "plant.v"], check=True)
        stages = []
        names = m.export("py-" + pattern, animate=True, steps=3,
                         progress=lambda stage, image: stages.append(stage))
        assert names == ["py-" + pattern % k for k in (1, 2, 3)], pattern
        assert stages == ["derive", "frame", "frame", "frame"]
        for k in (1, 2, 3):
            cmd = (default_scene / ("cmd-" + pattern % k)).read_bytes()
            py = (default_scene / ("py-" + pattern % k)).read_bytes()
            if pattern.endswith(".ray"):  # the main object is named after the file
                cmd = cmd.replace(("cmd-" + pattern % k).encode(), b"")
                py = py.replace(("py-" + pattern % k).encode(), b"")
            assert len(py) > 500 and py == cmd, pattern % k
    # each frame's file is the still export of that frame's string
    for k in (1, 2, 3):
        m.export("still.glb", string=m.derive(steps=k))
        assert (default_scene / "still.glb").read_bytes() == \
            (default_scene / ("py-f%02d.glb" % k)).read_bytes(), k
    assert (default_scene / "py-f01.glb").read_bytes() != (default_scene / "py-f03.glb").read_bytes()
