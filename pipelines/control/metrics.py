"""Centring figures of a closed-loop run."""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class CentringSample:
    """The subject's ground-truth centre relative to the view centre at one frame's capture.

    ``dx``/``dy`` are signed offsets as fractions of the view diagonal (right, down positive).
    """

    t: float
    dx: float
    dy: float
    in_view: bool

    @property
    def error(self) -> float:
        return math.hypot(self.dx, self.dy)


def summarize(samples: Sequence[CentringSample], centred: float = 0.05) -> dict[str, float | int | None]:
    """Mean/RMS centring error, out-of-view fraction, time to first centre and overshoot.

    ``time_to_first_centre`` is the first time (from the first sample) the error is within
    ``centred``; ``overshoot`` is the largest excursion past the centre after that, along the
    initial offset's direction, as a fraction of the initial offset (0 when the subject started
    centred or never got there).
    """
    if not samples:
        raise ValueError("no samples")
    errors = [s.error for s in samples]
    n = len(samples)
    first = next((i for i, e in enumerate(errors) if e <= centred), None)
    s0 = samples[0]
    overshoot = 0.0
    if first is not None and s0.error > centred:
        ux, uy = s0.dx / s0.error, s0.dy / s0.error
        past = max(-(s.dx * ux + s.dy * uy) for s in samples[first:])
        overshoot = max(0.0, past) / s0.error
    return {
        "frames": n,
        "mean_center_error": sum(errors) / n,
        "rms_center_error": math.sqrt(sum(e * e for e in errors) / n),
        "out_of_view": sum(not s.in_view for s in samples) / n,
        "time_to_first_centre": None if first is None else samples[first].t - s0.t,
        "overshoot": overshoot,
    }
