# SPDX-License-Identifier: Apache-2.0
# Corpus models through Python write the command's bytes, with their own cpfg command
# lines turned into keywords.
import json
import os
import shlex
import subprocess

import pytest

import cambium

MODELS = [
    "11-CPFG/01-Introduction/01-quadratic-Koch",   # -m, line drawing
    "11-CPFG/01-Introduction/05-compound-homo",    # homomorphism
    "10-manuals/10-GettingStarted/01-Lychnis",     # -M materials, surfaces
    "10-manuals/11-CPFG/Sedge",                    # -m1 -m2 colour blocks
    "11-CPFG/04-Signaling/11-acropetal-1-signal",  # cpfg's -w, overridden below
    "10-manuals/15-VlabTools/FernLeaf",            # functions, contours, fonts
]
RENDER = ["-w", "72", "54", "--spp", "4"]


def keywords(words):
    """cpfg's command line (without "cpfg") as cambium.load's arguments."""
    files, kw = [], {}
    i = 0
    while i < len(words):
        w = words[i]
        if w[:2] in ("-m", "-M") and (len(w) == 2 or w[2:].isdigit()):
            key = "materials" if w[1] == "M" else "colormap"
            kw.setdefault(key, {})[int(w[2:] or 1)] = words[i + 1]
            i += 2
        elif w == "-w":
            kw["width"], kw["height"] = int(words[i + 1]), int(words[i + 2])
            i += 3
        elif w.startswith("-"):
            raise AssertionError(f"option {w} is not translated by this test")
        else:
            files.append(w)
            i += 1
    return files, kw


@pytest.mark.parametrize("model", MODELS)
def test_corpus_model_writes_the_commands_bytes(model, corpus, command, tmp_path, monkeypatch):
    folder = corpus / "cpfg" / model
    before = sorted(os.listdir(folder))
    words = shlex.split(json.loads((folder / "model.json").read_text())["command"])[1:]
    monkeypatch.chdir(folder)  # cpfg runs in the model's folder; outputs go to tmp_path
    subprocess.run([command, "-q", *words, *RENDER, "-o", str(tmp_path / "cmd.png"), "-o",
                    str(tmp_path / "cmd.exr")], check=True)
    files, kw = keywords(words)
    kw.update(width=72, height=54, spp=4)
    img = cambium.load(*files, quiet=True, **kw).render()
    img.write(tmp_path / "py.png")
    img.write(tmp_path / "py.exr")
    for ext in ("png", "exr"):
        assert (tmp_path / f"py.{ext}").read_bytes() == (tmp_path / f"cmd.{ext}").read_bytes(), ext
    assert sorted(os.listdir(folder)) == before  # nothing written into the corpus
