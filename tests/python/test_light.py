# SPDX-License-Identifier: Apache-2.0
# The light report: the command's file, and its numbers as Python values.
import json
import subprocess

import pytest

import cambium


def test_light_report_is_the_commands(default_scene, command):
    for ext in ("json", "csv"):
        subprocess.run([command, "-q", "-M", "plant.mat", "--light-report", f"cmd.{ext}",
                        "--light-rays", "20000", "plant.l", "plant.v"], check=True)
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    report = m.light_report(light_rays=20000)
    assert report == json.loads((default_scene / "cmd.json").read_text())
    assert report["organs"] and report["total_absorbed"] > 0
    assert m.light_report("py.json", light_rays=20000) == report
    assert m.light_report("py.csv", light_rays=20000) is None
    for ext in ("json", "csv"):
        assert (default_scene / f"py.{ext}").read_bytes() == \
            (default_scene / f"cmd.{ext}").read_bytes()


def test_an_edited_string_changes_the_report(default_scene):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    s = m.derive()
    before = m.light_report(string=s, light_rays=20000)
    for i in s.find("L"):  # the leaves twice as large
        s.parameters[s.offsets[i]] *= 2
    after = m.light_report(string=s, light_rays=20000)
    assert after["total_absorbed"] != pytest.approx(before["total_absorbed"], rel=1e-3)
