"""The clockwise mirror (thesis 6.3.2): mirrored legal moves are exactly the mirror images."""

from __future__ import annotations

import numpy as np
import pytest

from graspgait_env.gait import GaitModel
from graspgait_env.planners.mirror import mirror_state, mirrored


@pytest.mark.parametrize("name", ["ellipse", "pentagon"])
def test_mirrored_moves_are_the_mirror_images(name):
    model = GaitModel(name, 0.7, n=90)
    mm = mirrored(model)
    rng = np.random.default_rng(0)
    starts = model.start_states()
    for i in rng.choice(len(starts), 15, replace=False):
        s = starts[int(i)]
        for _ in range(4):  # a few random legal moves away from theta = 0 as well
            ms = mirror_state(s, model.n)
            assert mm.is_legal_state(ms) and mirror_state(ms, model.n) == s
            ours = {t for _, t in model.successors(s)}
            theirs = {mirror_state(t, model.n) for _, t in mm.successors(ms)}
            assert ours == theirs
            s = sorted(ours)[int(rng.integers(len(ours)))]
    # the model itself is untouched, and mirroring twice gives its workspaces back
    assert not np.shares_memory(mm.stable, model.stable)
    twice = mirrored(mm)
    np.testing.assert_array_equal(twice.stable, model.stable)
    np.testing.assert_array_equal(twice.ws_start % model.n, model.ws_start % model.n)
