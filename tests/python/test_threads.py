# SPDX-License-Identifier: Apache-2.0
# Calls from several Python threads: they run one at a time, each as it would alone.
import threading

import numpy as np

import cambium

SMALL = dict(width=64, height=48, spp=2)


def test_renders_from_several_threads_are_each_the_lone_render(default_scene):
    m = cambium.load("plant.l", "plant.v", materials="plant.mat")
    strings = [m.derive(steps=k) for k in (2, 4, 6)]
    alone = [np.asarray(m.render(string=s, **SMALL)) for s in strings]
    results = {}

    def render(k):
        results[k] = np.asarray(m.render(string=strings[k], **SMALL))

    threads = [threading.Thread(target=render, args=(k,)) for k in range(3)]
    for t in threads:
        t.start()
    # meanwhile, this thread edits a string with names the L-system never used
    edited = m.derive(steps=1)
    for k in range(50):
        edited.insert(0, f"Y{k % 7}(1)")
    for t in threads:
        t.join()
    assert len(edited) == len(m.derive(steps=1)) + 100  # "Yk(1)" is two modules
    for k in range(3):
        assert np.array_equal(results[k], alone[k]), k
