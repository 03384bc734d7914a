"""The correlation filter's scale follows the subject only as far as ``min_scale`` and
``max_scale`` (of its first size) allow."""
from __future__ import annotations

import pytest

from tracker.backends.dcf import DcfBackend, DcfSettings
from tracker.evaluation.synthetic import render_sequence


@pytest.mark.parametrize("change, bound", [(1.6, "max"), (0.5, "min")])
def test_the_box_stops_at_the_scale_bound(change: float, bound: str) -> None:
    seq = render_sequence(frames=40, target=40, speed=0.7, scale_change=change, seed=6)
    settings = DcfSettings(min_scale=0.8, max_scale=1.2)
    backend = DcfBackend(settings)
    backend.init(seq.frames[0], seq.boxes[0])
    widths = [backend.update(frame)[0][2] for frame in seq.frames[1:]]
    if bound == "max":
        assert 1.15 * 40 < max(widths) <= settings.max_scale * 40
    else:
        assert settings.min_scale * 40 <= min(widths) < 0.85 * 40
