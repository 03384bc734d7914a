"""What the console needs from the loop: the frame record it shows, and the operator's actions.

Every action returns at once: the loop runs it on its own thread at the start of its next step,
so a request never races the tracker or the keep-alive. What came of it shows in ``state()``.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Protocol

#: Live settings the console may change, with their ranges (the controller checks them again).
#: ``max_speed`` in deg/s (the protocol's limit is 360), ``dead_zone`` in degrees of error the
#: gimbal ignores, ``kp``/``ki``/``kd`` the PID gains (deg/s per deg, per deg*s, per deg/s).
SETTING_RANGES: Mapping[str, tuple[float, float]] = {
    "max_speed": (1.0, 360.0),
    "dead_zone": (0.0, 10.0),
    "kp": (0.0, 100.0),
    "ki": (0.0, 50.0),
    "kd": (0.0, 10.0),
}


@dataclass(frozen=True)
class ConsoleView:
    """One processed frame as the console shows it (boxes in pixels of the source frame); the
    sink's ``describe`` makes it from the loop's own record."""

    frame_index: int
    capture_t: float  # time.monotonic() of the capture
    state: str  # acquiring, tracking, searching, lost, paused
    box: tuple[float, float, float, float] | None
    confidence: float | None
    rates_dps: tuple[float, float]
    candidates: tuple[tuple[float, float, float, float], ...] = ()  # the detector's boxes, when it ran


class ConsoleOperator(Protocol):
    """The loop, as the console drives it. Calls come from the console's thread."""

    def select(self, box: tuple[float, float, float, float]) -> None:
        """Start (or restart) tracking on ``box`` in the next frame."""

    def pause(self) -> None:
        """Zero speed, then release: the gimbal holds where it is; the state reads ``paused``."""

    def resume(self) -> None:
        """Follow the subject again after ``pause`` or ``recenter``."""

    def recenter(self) -> None:
        """Pause, then send the gimbal home (the protocol's recenter)."""

    def set_recording(self, on: bool) -> None:
        """Camera recording on or off."""

    def stop(self) -> None:
        """End the run as a finished one: the gimbal stops, outputs are finalised, exit status 0."""

    def apply_settings(self, changes: Mapping[str, float]) -> None:
        """Apply live settings (keys of ``SETTING_RANGES``); raises ValueError for a value the
        controller refuses, before anything is changed."""

    def frame_size(self) -> tuple[int, int] | None:
        """The source frame's width and height (None before the first frame)."""

    def state(self) -> dict[str, Any]:
        """The run's status as JSON-ready values: fps, latency, bus health, recording, settings..."""
