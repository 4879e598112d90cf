# SPDX-License-Identifier: Apache-2.0
# Images: numpy reads them in place; they are written as the command writes them.
import subprocess

import numpy as np

import cambium

SMALL = dict(width=40, height=30, spp=2)


def test_asarray_is_height_by_width_rgba_without_a_copy(default_scene):
    img = cambium.load("plant.l", "plant.v", materials="plant.mat").render(**SMALL)
    a = np.asarray(img)
    assert a.shape == (30, 40, 4)
    assert a.dtype == np.float32
    assert (img.width, img.height) == (40, 30)
    # two arrays over the image's own memory: a write through one shows in the other
    b = np.asarray(img)
    assert np.shares_memory(a, b)
    a[3, 5, 1] = 1234.5
    assert b[3, 5, 1] == 1234.5
    assert np.asarray(img)[3, 5, 1] == 1234.5
    # the plant covers some pixels, not all
    assert 0 < np.count_nonzero(a[:, :, 3] > 0) < 40 * 30


def test_layers_are_arrays_over_the_image(default_scene):
    img = cambium.load("plant.l", "plant.v", materials="plant.mat").render(**SMALL)
    assert img.albedo.shape == (30, 40, 3)
    assert img.normal.shape == (30, 40, 3)
    assert img.depth.shape == (30, 40)
    assert np.isfinite(img.depth).any() and np.isinf(img.depth).any()
    plain = cambium.load("plant.l", "plant.v", materials="plant.mat").render(layers=False, **SMALL)
    assert plain.albedo is None and plain.depth is None
    # the layers cost time, not pixels
    assert np.array_equal(np.asarray(plain), np.asarray(img))


def test_png_and_exr_are_the_commands_bytes(default_scene, command):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    img = m.render(width=64, height=48, spp=4, tonemap="filmic", exposure=0.5)
    img.write("py.png")
    img.write("py.exr")
    subprocess.run([command, "-q", "-M", "plant.mat", "-w", "64", "48", "--spp", "4",
                    "--tonemap", "filmic", "--exposure", "0.5", "-o", "cmd.png", "-o",
                    "cmd.exr", "plant.l", "plant.v"], check=True)
    for ext in ("png", "exr"):
        ours = (default_scene / f"py.{ext}").read_bytes()
        theirs = (default_scene / f"cmd.{ext}").read_bytes()
        assert ours == theirs, ext
    # the notebook's PNG is the same file
    assert img._repr_png_() == (default_scene / "py.png").read_bytes()


def test_a_write_error_is_a_cambium_error(default_scene):
    img = cambium.load("plant.l", "plant.v", materials="plant.mat").render(**SMALL)
    try:
        img.write("no-such-folder/x.png")
    except cambium.Error as e:
        assert "no-such-folder" in str(e)
    else:
        raise AssertionError("no error")
