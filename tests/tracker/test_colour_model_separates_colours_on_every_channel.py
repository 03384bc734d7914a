"""The colour model's histogram is joint over blue, green and red: a subject that differs from its
background in one channel only is still told apart from it."""
from __future__ import annotations

import numpy as np
import pytest

from tracker.colour_model import ColourModel, colour_index


@pytest.mark.parametrize("channel", [0, 1, 2], ids=["blue", "green", "red"])
def test_a_subject_differing_in_one_channel_is_told_apart(channel: int) -> None:
    patch = np.full((20, 20, 3), 60, np.uint8)
    patch[5:15, 5:15, channel] = 220
    foreground = np.zeros((20, 20), bool)
    foreground[5:15, 5:15] = True
    model = ColourModel()
    model.learn(colour_index(patch), foreground, ~foreground, rate=1.0)
    likelihood = model.likelihood(colour_index(patch))
    assert likelihood[10, 10] > 0.9 and likelihood[1, 1] < 0.1
