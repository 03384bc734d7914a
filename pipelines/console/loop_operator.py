"""The console's operator for the track loop: each action goes to the loop's thread through
``loop.submit`` with a note, which the telemetry line of the frame it ran at carries."""
from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from gimbal.messages import ParameterPush
from pipelines.console.operator import ConsoleView
from pipelines.control.tuning import retuned, settings_of
from pipelines.outputs.latency import latency_percentiles

if TYPE_CHECKING:
    from gimbal.client import GimbalClient
    from pipelines.control.camera import CameraModel
    from pipelines.loop import FrameRecord, Loop

CONSOLE_STOP = "stopped from the console"
SILENT_AFTER_S = 1.0  # no attitude push for this long: the gimbal is silent
LATENCY_WINDOW = 300  # the status's latency percentiles are over this many recent commands
FPS_WINDOW_S = 2.0
def describe(record: FrameRecord) -> ConsoleView:
    """What the console shows of one of the loop's records."""
    estimate = record.estimate
    return ConsoleView(
        record.index, record.t, record.state,
        None if estimate is None else tuple(estimate.box), None if estimate is None else estimate.confidence,
        (record.command.yaw_dps, record.command.pitch_dps), tuple(tuple(d.box) for d in record.candidates))


class LoopOperator:
    """``ConsoleOperator`` for ``loop``; ``source_description``, ``frame_size``, ``client`` and
    ``camera`` are the run's. Calls come from the console's thread; the loop's state is only read
    here (frozen values and counters), never changed but through ``submit``."""

    name = "console operator"

    def __init__(self, loop: Loop, *, source_description: str, frame_size: tuple[int, int],
                 client: GimbalClient, camera: CameraModel) -> None:
        self.loop = loop
        self.source_description = source_description
        self._frame_size = frame_size
        self.client = client
        self.camera = camera
        self._lock = threading.Lock()
        self._frame_times: deque[float] = deque()

    # -- actions (queued for the loop's thread) ---------------------------------------------
    def select(self, box: tuple[float, float, float, float]) -> None:
        self.loop.submit(lambda: self.loop.start_tracking(box), {"action": "select", "box": list(box)})

    def pause(self) -> None:
        self.loop.submit(self.loop.pause, {"action": "pause"})

    def resume(self) -> None:
        self.loop.submit(self.loop.resume, {"action": "resume"})

    def recenter(self) -> None:
        self.loop.submit(self.loop.recenter, {"action": "recenter"})

    def set_recording(self, on: bool) -> None:
        action = self.loop.start_recording if on else self.loop.stop_recording
        self.loop.submit(action, {"action": "record", "on": on})

    def stop(self) -> None:
        self.loop.submit(lambda: self.loop.stop(CONSOLE_STOP), {"action": "stop"})

    def apply_settings(self, changes: Mapping[str, float]) -> None:
        """Checked here against the controller's current config (ValueError before anything is
        queued), applied on the loop's thread to the config as it stands then."""
        retuned(self.loop.controller.config, changes)
        self.loop.submit(lambda: self.loop.retune(retuned(self.loop.controller.config, changes)),
                         {"action": "settings", **changes})

    # -- what the console shows -------------------------------------------------------------
    def frame_size(self) -> tuple[int, int]:
        return self._frame_size

    def dead_zone_px(self) -> float:
        """The dead band's half-width at the image centre, in source pixels."""
        return self.camera.focal_px * math.tan(math.radians(self.loop.controller.config.deadband_deg))

    def on_frame(self, record: FrameRecord, frame: Any) -> None:
        """A sink of its own, for the loop's fps: one time per frame."""
        now = time.monotonic()
        with self._lock:
            self._frame_times.append(now)
            while self._frame_times[0] < now - FPS_WINDOW_S:
                self._frame_times.popleft()

    def close(self) -> None:
        """Nothing to finalise."""

    def fps(self) -> float | None:
        with self._lock:
            times = list(self._frame_times)
        if len(times) < 2 or times[-1] <= times[0]:
            return None
        return (len(times) - 1) / (times[-1] - times[0])

    def state(self) -> dict[str, Any]:
        link, loop = self.loop.gimbal, self.loop
        stats = link.stats()
        latency = latency_percentiles(link.latencies()[-LATENCY_WINDOW:])
        attitude = link.latest()
        push = self.client.latest(ParameterPush)
        recorder = loop.recorder
        return {
            "source": self.source_description, "fps": self.fps(), "paused": loop.paused,
            "latency_ms": {k: None if latency[k] is None else latency[k] * 1000.0 for k in ("p50", "p99")},
            "attitude_deg": None if attitude is None else [attitude.yaw, attitude.pitch, attitude.roll],
            "bus": {"timeouts": stats.get("reply_timeouts", 0), "nacks": stats.get("reply_errors", 0),
                    "send_errors": stats.get("send_errors", 0),
                    "silent": push is None or time.monotonic() - push[1] > SILENT_AFTER_S},
            "recording": {"on": recorder is not None and recorder.active,
                          **({} if recorder is None else recorder.status)},
            "settings": settings_of(loop.controller.config),
        }
