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


def edit_axiom(default_scene, tmp_path, new_axiom):
    """scenes/default with another axiom, loaded from a folder of its own."""
    folder = tmp_path / "edited"
    shutil.copytree(default_scene, folder)
    edit_lsystem(folder, "axiom: ;(1)!(0.55)F(2.2)!(0.4)A(2.0,0.4)", "axiom: " + new_axiom)
    return cambium.load(folder / "plant.l", folder / "plant.v", materials=folder / "plant.mat")


def test_structural_edits_render_as_the_same_edits_in_the_file(default_scene, tmp_path):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    axiom = m.derive(steps=0)  # ;(1)!(0.55)F(2.2)!(0.4)A(2.0,0.4)
    branched = m.derive(steps=0)
    branched.insert(3, "[+(60)F(1.5)]")
    assert len(branched) == len(axiom) + 4
    assert [branched[i][0] for i in range(3, 8)] == ["[", "+", "F", "]", "!"]
    assert branched[5] == ("F", (1.5,))
    shorter = m.derive(steps=0)
    del shorter[2]  # F(2.2)
    replaced = m.derive(steps=0)
    replaced.replace(2, 3, "F(1)F(1.2)")
    sliced = m.derive(steps=0)
    del sliced[1:3]
    cases = [(branched, ";(1)!(0.55)F(2.2)[+(60)F(1.5)]!(0.4)A(2.0,0.4)"),
             (shorter, ";(1)!(0.55)!(0.4)A(2.0,0.4)"),
             (replaced, ";(1)!(0.55)F(1)F(1.2)!(0.4)A(2.0,0.4)"),
             (sliced, ";(1)!(0.4)A(2.0,0.4)")]
    original = np.asarray(m.render(string=axiom, **SMALL))
    for edited, in_file in cases:
        picture = np.asarray(m.render(string=edited, **SMALL))
        expected = np.asarray(edit_axiom(default_scene, tmp_path / str(len(edited)),
                                         in_file).render(steps=0, **SMALL))
        assert np.array_equal(picture, expected), in_file
        assert not np.array_equal(picture, original), in_file


def test_a_string_parsed_from_text_is_the_derived_one(default_scene):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    s = m.derive()
    parsed = m.parse(str(s))
    assert np.array_equal(parsed.symbols, s.symbols)
    assert np.array_equal(parsed.counts, s.counts)
    assert np.allclose(parsed.parameters, s.parameters, rtol=1e-5)  # -str prints %g
    assert len(m.parse("")) == 0


def test_a_name_the_lsystem_never_used_is_added_and_means_nothing(default_scene):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    s = m.derive(steps=1)
    assert "Y" not in s.names
    picture = np.asarray(m.render(string=s, **SMALL))
    s.insert(0, "Y(3)")
    assert s[0] == ("Y", (3.0,)) and "Y" in s.names
    assert np.array_equal(np.asarray(m.render(string=s, **SMALL)), picture)


def test_bad_edits_are_errors_and_leave_the_string_as_it_was(default_scene):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat", max_modules=8)
    s = m.derive(steps=0)
    text = str(s)
    with pytest.raises(cambium.Error) as caught:
        s.insert(0, "F(1")  # no closing parenthesis
    assert caught.value.file == "<string text>"
    with pytest.raises(cambium.Error, match="max_modules"):
        s.insert(0, "FFFF")  # 9 modules, past the load's limit of 8
    with pytest.raises(IndexError):
        s.insert(len(s) + 1, "F")
    with pytest.raises(IndexError):
        s.replace(3, 2, "F")
    with pytest.raises(ValueError):
        del s[::2]
    assert str(s) == text
    s.insert(len(s), "F")  # appends
    assert s[-1] == ("F", ())
