"""Centring figures of a closed-loop run."""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

#: The largest error a frame can score (fraction of the view diagonal): a subject in the view's
#: corner. A subject further out, or behind the view, scores this, so mean and RMS do not depend on
#: where a lost subject drifted to.
MAX_ERROR = 0.5
#: How long after the first centring the overshoot is looked for (seconds): the step response, not
#: the later tracking of a moving subject.
OVERSHOOT_WINDOW_S = 0.5


@dataclass(frozen=True, slots=True)
class CentringSample:
    """The subject's ground-truth centre relative to the view centre at one frame's capture.

    ``dx``/``dy`` are signed offsets as fractions of the view diagonal (right, down positive), at
    most ``MAX_ERROR`` long.
    """

    t: float
    dx: float
    dy: float
    in_view: bool

    @property
    def error(self) -> float:
        return math.hypot(self.dx, self.dy)


def summarize(samples: Sequence[CentringSample | None], centred: float = 0.05) -> dict[str, float | int | None]:
    """Mean/RMS centring error, out-of-view fraction, time to first centre and overshoot.

    ``None`` is a frame without ground truth: counted in ``frames``, left out of every figure
    (``frames_scored`` counts the others). ``time_to_first_centre`` is the time from the first
    scored frame until the error is first within ``centred``; ``overshoot`` is the step response's,
    see ``step_overshoot``.
    """
    scored = [s for s in samples if s is not None]
    if not scored:
        raise ValueError("no frame with ground truth to score")
    errors = [s.error for s in scored]
    n = len(scored)
    first = next((i for i, e in enumerate(errors) if e <= centred), None)
    return {
        "frames": len(samples),
        "frames_scored": n,
        "mean_center_error": sum(errors) / n,
        "rms_center_error": math.sqrt(sum(e * e for e in errors) / n),
        "out_of_view": sum(not s.in_view for s in scored) / n,
        "time_to_first_centre": None if first is None else scored[first].t - scored[0].t,
        "overshoot": step_overshoot(scored, first, centred),
    }


def step_overshoot(samples: Sequence[CentringSample], first: int | None, centred: float) -> float:
    """The largest excursion past the centre, along the initial offset's direction, within
    ``OVERSHOOT_WINDOW_S`` of the first centring (sample ``first``), as a fraction of the initial
    offset; 0 when the subject started within ``centred`` or never got there."""
    s0 = samples[0]
    if first is None or s0.error <= centred:
        return 0.0
    ux, uy = s0.dx / s0.error, s0.dy / s0.error
    end = samples[first].t + OVERSHOOT_WINDOW_S
    past = max(-(s.dx * ux + s.dy * uy) for s in samples[first:] if s.t <= end)
    return max(0.0, past) / s0.error
