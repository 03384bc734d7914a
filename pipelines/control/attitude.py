"""Timestamped gimbal attitude, interpolated at a frame's capture time."""
from __future__ import annotations

import bisect
from collections import deque
from dataclasses import dataclass
from operator import attrgetter

from pipelines.control.direction import wrap_deg


@dataclass(frozen=True, slots=True)
class Attitude:
    """Gimbal attitude in degrees at ``timestamp`` (yaw wrapped into [-180, 180))."""

    yaw: float
    roll: float
    pitch: float
    timestamp: float


class AttitudeHistory:
    """A bounded history of attitude samples; ``at(t)`` interpolates (yaw across the +-180 wrap).

    Samples must arrive in time order (older ones are dropped). Beyond the newest sample the
    attitude is extrapolated from the last two samples for at most ``max_extrapolation`` seconds,
    then held; before the oldest sample the oldest is returned.
    """

    def __init__(self, maxlen: int = 256, max_extrapolation: float = 0.1) -> None:
        if maxlen < 2:
            raise ValueError("maxlen must be at least 2")
        self.max_extrapolation = max_extrapolation
        self._samples: deque[Attitude] = deque(maxlen=maxlen)

    def __len__(self) -> int:
        return len(self._samples)

    def add(self, timestamp: float, yaw: float, roll: float, pitch: float) -> None:
        """Record an attitude in degrees; a sample older than the newest is ignored."""
        if self._samples and timestamp < self._samples[-1].timestamp:
            return
        self._samples.append(Attitude(wrap_deg(yaw), roll, pitch, timestamp))

    def latest(self) -> Attitude | None:
        return self._samples[-1] if self._samples else None

    def at(self, t: float) -> Attitude | None:
        """The attitude at time ``t``; ``None`` when no sample was recorded."""
        s = self._samples
        if not s:
            return None
        if t <= s[0].timestamp:
            return s[0]
        if t >= s[-1].timestamp:
            if len(s) < 2:
                return s[-1]
            a, b = s[-2], s[-1]
            t = min(t, b.timestamp + self.max_extrapolation)
        else:
            i = bisect.bisect_right(s, t, key=attrgetter("timestamp"))
            a, b = s[i - 1], s[i]
        span = b.timestamp - a.timestamp
        if span <= 0.0:
            return b
        f = (t - a.timestamp) / span
        return Attitude(
            wrap_deg(a.yaw + f * wrap_deg(b.yaw - a.yaw)),
            a.roll + f * (b.roll - a.roll),
            a.pitch + f * (b.pitch - a.pitch),
            t,
        )
