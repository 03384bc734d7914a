"""What one step of the loop produced for one frame: the record every sink receives."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from gimbal.other_hosts import OtherHostsSeen
    from gimbal.watchdog import BusHealth
    from pipelines.control.attitude import Attitude
    from pipelines.control.controller import RateCommand
    from tracker.detectors import Detection
    from tracker.runtime.estimate import TargetEstimate

#: ``FrameRecord.state`` before the subject is chosen (no estimate yet).
ACQUIRING = "acquiring"
#: ``FrameRecord.state`` while an operator has paused the gimbal.
PAUSED = "paused"


@dataclass(frozen=True, slots=True, eq=False)
class FrameRecord:
    """One frame through the loop. Times share the loop's monotonic clock: ``t`` is the frame's
    capture time (the one the tracker and the attitude lookup used), ``t_run`` the time since the
    loop started when the command was chosen, ``t_video`` where the frame sits in a recording
    (``None`` for a live source)."""

    index: int
    t: float
    t_run: float
    t_video: float | None
    estimate: TargetEstimate | None  # None until the subject is chosen
    command: RateCommand  # as the controller chose it, before the gimbal's sign conventions
    attitude: Attitude | None  # the newest attitude the gimbal reported, as it reported it
    dropped: int  # frames the source has dropped so far
    recording: bool  # the camera was recording (a start was answered and no stop yet)
    candidates: tuple[Detection, ...] = ()  # the detector's candidates of this frame, if it ran
    paused: bool = False  # an operator paused the gimbal: no command was sent for this frame
    operator: tuple[dict[str, Any], ...] = ()  # what an operator did at the start of this step
    bus: BusHealth | None = None  # the gimbal link's state after this frame's command (None: not streaming)
    other_hosts: OtherHostsSeen | None = None  # what other hosts sent to the gimbal so far

    @property
    def state(self) -> str:
        """``tracking``, ``searching``, ``lost`` or ``acquiring``; ``paused`` while paused."""
        if self.paused:
            return PAUSED
        return ACQUIRING if self.estimate is None else self.estimate.state.value

    @property
    def found(self) -> bool:
        return self.estimate is not None and self.estimate.found

    @property
    def error_deg(self) -> tuple[float, float] | None:
        """The command's (yaw, pitch) angular error; None when no subject stood behind it."""
        c = self.command
        return None if math.isnan(c.yaw_error_deg) else (c.yaw_error_deg, c.pitch_error_deg)

    @property
    def angular_error_deg(self) -> float | None:
        """The length of ``error_deg``."""
        error = self.error_deg
        return None if error is None else math.hypot(*error)

    @property
    def latency_s(self) -> float:
        """From the frame's capture to the command's choice."""
        return self.command.latency_s
