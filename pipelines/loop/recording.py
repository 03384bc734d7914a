"""Camera recording through the gimbal: started when the subject is first acquired (if asked),
stopped at the end, and on an operator's word in between; what happened is kept for the summary."""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from gimbal.errors import GimbalError

if TYPE_CHECKING:
    from gimbal.client import GimbalClient


class Recorder:
    """Record starts and stops for one client. ``status`` is the summary's ``recording`` object:
    ``requested``, then ``started``/``start_confirmed``, ``stopped``/``stop_confirmed`` and any
    ``error``. An answered action counts as done (so a start is always followed by a stop),
    confirmed or not; a refused one is recorded, never raised."""

    def __init__(self, client: GimbalClient, requested: bool = False) -> None:
        self.client = client
        self.requested = requested
        self.status: dict[str, Any] = {"requested": requested}
        self._acquired = False

    @property
    def active(self) -> bool:
        """A start was answered and no stop since."""
        return bool(self.status.get("started")) and not self.status.get("stopped")

    def on_acquired(self) -> None:
        """The subject was found for the first time: start recording if that was asked for."""
        first, self._acquired = not self._acquired, True
        if first and self.requested:
            self.start()

    def start(self) -> None:
        if not self.active:
            self._camera_action(self.client.start_recording, "started", "start_confirmed", recording=True)
            if self.status.get("started"):
                self.status.pop("stopped", None)
                self.status.pop("stop_confirmed", None)

    def stop(self) -> None:
        if self.active:
            self._camera_action(self.client.stop_recording, "stopped", "stop_confirmed", recording=False)

    def restore(self) -> None:
        """The gimbal was taken back after a silence: a recording that should be running is started
        again if the camera stopped meanwhile (a gimbal power-cycled); ``status["restarts"]`` counts it."""
        if not self.active:
            return
        try:
            if self.client.camera_status():
                return
        except GimbalError as exc:
            self.status["status_query_error"] = str(exc)
            return
        self.status["restarts"] = self.status.get("restarts", 0) + 1
        self._camera_action(self.client.start_recording, "started", "start_confirmed", recording=True)

    def finish(self) -> None:
        """At the end of a run: say why a requested recording never started, stop a running one."""
        if self.requested and not self._acquired:
            self.status["started"] = False
            self.status["error"] = "the subject was never acquired"
        self.stop()

    def _camera_action(self, action: Callable[[], None], done: str, confirmed: str, recording: bool) -> None:
        """Send a record start or stop, then ask the camera whether it is ``recording``."""
        try:
            action()
        except GimbalError as exc:
            self.status[done] = False
            self.status["error"] = str(exc)
            return
        self.status[done] = True
        try:
            self.status[confirmed] = self.client.camera_status() is recording
        except GimbalError as exc:
            self.status[confirmed] = False
            self.status["status_query_error"] = str(exc)
