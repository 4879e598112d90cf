# SPDX-License-Identifier: Apache-2.0
# Fixtures of the Python module's tests: the command beside the module, the corpus, and
# models copied into a temporary folder.
import os
import pathlib
import shutil

import pytest

SOURCE = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def command():
    """The cambium command of the same build (CAMBIUM_EXE, set by ctest)."""
    exe = os.environ.get("CAMBIUM_EXE")
    if not exe or not os.path.exists(exe):
        pytest.skip("CAMBIUM_EXE does not name the cambium command")
    return exe


@pytest.fixture(scope="module")
def corpus():
    """The model corpus: $CAMBIUM_CORPUS, else the build's default (../shared/corpus)."""
    folder = os.environ.get("CAMBIUM_CORPUS") or os.environ.get("CAMBIUM_CORPUS_DEFAULT")
    if not folder or not os.path.isdir(os.path.join(folder, "cpfg")):
        pytest.skip("the model corpus is not there (../shared/corpus or $CAMBIUM_CORPUS)")
    return pathlib.Path(folder)


@pytest.fixture
def default_scene(tmp_path):
    """scenes/default copied into a folder of its own (the working folder meanwhile)."""
    folder = tmp_path / "default"
    shutil.copytree(SOURCE / "scenes" / "default", folder)
    old = os.getcwd()
    os.chdir(folder)
    yield folder
    os.chdir(old)
