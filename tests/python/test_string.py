# SPDX-License-Identifier: Apache-2.0
# The derived string as arrays: an edit in Python renders as the same edit in the .l file.
import shutil

import numpy as np
import pytest

import cambium

SMALL = dict(width=64, height=48, spp=2)


def test_string_arrays_agree_with_the_modules(default_scene):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    s = m.derive(steps=2)
    assert len(s) == len(s.symbols) == len(s.counts) == len(s.offsets)
    assert s.offsets[-1] + s.counts[-1] == len(s.parameters)
    assert [s[i][0] for i in range(3)] == [";", "!", "F"]
    # no step: the axiom ;(1)!(0.55)F(2.2)!(0.4)A(2.0,0.4)
    s = m.derive(steps=0)
    assert len(s) == 5
    assert s[0] == (";", (1.0,))
    assert s[1][0] == "!" and s[1][1] == pytest.approx((0.55,))
    assert s.names[s.symbols[2]] == "F"
    assert s.parameters[s.offsets[2]] == pytest.approx(2.2)
    assert str(s).startswith(";(1)!(0.55)F(2.2)")
    assert s[4] == ("A", (2.0, pytest.approx(0.4)))
    assert len(m.derive(steps=3)) > len(m.derive(steps=2)) > len(m.derive(steps=1)) > len(s)
    # the derivation length of the file by default
    assert len(m.derive()) == len(m.derive(steps=m.derivation_length))


def edit_lsystem(folder, old, new):
    text = (folder / "plant.l").read_text()
    assert text.count(old) == 1
    (folder / "plant.l").write_text(text.replace(old, new))


@pytest.mark.parametrize("how", ["set_parameter", "numpy"])
def test_a_parameter_edited_in_python_renders_as_the_same_edit_in_the_file(default_scene, tmp_path,
                                                                           how):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    # the trunk's colour index, which no production rewrites: ;(1) becomes ;(2)
    s = m.derive()
    trunk = s.find(";")[0]
    assert trunk == 0 and s[trunk] == (";", (1.0,))
    if how == "set_parameter":
        s.set_parameter(trunk, 0, 2.0)
    else:
        s.parameters[s.offsets[trunk]] = 2.0
    assert s[trunk] == (";", (2.0,))
    edited = np.asarray(m.render(string=s, **SMALL))

    folder = tmp_path / "edited"
    shutil.copytree(default_scene, folder)
    edit_lsystem(folder, "axiom: ;(1)!(0.55)", "axiom: ;(2)!(0.55)")
    in_file = np.asarray(cambium.load(folder / "plant.l", folder / "plant.v",
                                      materials=folder / "plant.mat").render(**SMALL))
    original = np.asarray(m.render(**SMALL))
    assert np.array_equal(edited, in_file)
    assert not np.array_equal(edited, original)


def test_a_string_of_another_model_is_refused(default_scene):
    a = cambium.load("plant.l", "plant.v", materials="plant.mat")
    b = cambium.load("plant.l", "plant.v", materials="plant.mat")
    with pytest.raises(cambium.Error, match="another model"):
        b.render(string=a.derive(steps=1), **SMALL)


def test_module_indices_are_checked(default_scene):
    s = cambium.load("plant.l", "plant.v", materials="plant.mat").derive(steps=1)
    with pytest.raises(IndexError):
        s[len(s)]
    with pytest.raises(IndexError):
        s.set_parameter(0, 1, 2.0)  # ;(1) has one parameter
    assert s[-1] == s[len(s) - 1]
    assert len(s.find("no-such-module")) == 0


def test_view_settings(default_scene):
    view = cambium.load("plant.l", "plant.v", materials="plant.mat").view
    text = (default_scene / "plant.v").read_text()
    assert view["file"].endswith("plant.v")
    assert view["projection"] in ("parallel", "perspective")
    assert ("perspective" in text) == (view["projection"] == "perspective")
    assert len(view["viewpoint"]) == 3


def test_a_derivation_advanced_step_by_step_gives_each_steps_string(default_scene):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    d = m.derivation()
    assert d.steps_done == 0 and d.derivation_length == m.derivation_length
    assert str(d.string) == str(m.derive(steps=0))
    for step in range(1, 4):
        s = d.advance()
        assert d.steps_done == step
        assert str(s) == str(m.derive(steps=step))
    # the step's string renders like any other
    img = m.render(string=d.advance(2), **SMALL)
    assert np.array_equal(np.asarray(img), np.asarray(m.render(steps=5, **SMALL)))
