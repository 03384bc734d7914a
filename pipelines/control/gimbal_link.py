"""Control's one window onto the gimbal: the attitude it reports, in this project's signs and
degrees and kept as a history, and the speed setpoints streamed back with the gimbal's own signs.

Everything control needs to know about the DJI R SDK and the client comes through here (the
push message, the keep-alive's setpoint age, the command range), so the rest of
``pipelines.control`` works in degrees and never sees a wire unit or a message class.
"""
from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

from gimbal.keepalive import DEFAULT_MAX_AGE_S
from gimbal.messages.limits import MAX_SPEED_DPS
from gimbal.messages.telemetry import ParameterPush
from gimbal.watchdog import DEFAULT_TIMEOUT_S
from pipelines.control.attitude import Attitude, AttitudeHistory

if TYPE_CHECKING:
    from gimbal.client import GimbalClient
    from gimbal.other_hosts import OtherHostsSeen
    from gimbal.watchdog import BusHealth
    from gimbal.keepalive import SpeedStreamer

#: The keep-alive streams zero once a setpoint is this old (the controller restarts from rest then).
SETPOINT_MAX_AGE_S = DEFAULT_MAX_AGE_S
#: The document's speed command range, ± this many °/s (every setpoint is clamped into it).
PROTOCOL_MAX_SPEED_DPS = MAX_SPEED_DPS


class Rates(Protocol):
    """What the link streams: a controller's yaw/pitch setpoint in °/s (its ``RateCommand``),
    named here so that the link does not import the controller that imports it."""

    yaw_dps: float
    pitch_dps: float


@dataclass(frozen=True)
class Signs:
    """+1 or -1 per axis: a gimbal that turns the other way for a positive speed (``yaw_speed``, seen
    on an RS 5), or reports its angle with the opposite sign (``yaw_attitude``). The two are
    independent: one RS 5 turns the other way and still reports its angles the usual way."""

    yaw_speed: int = 1
    pitch_speed: int = 1
    yaw_attitude: int = 1
    pitch_attitude: int = 1

    def __post_init__(self) -> None:
        for name, value in vars(self).items():
            if value not in (1, -1):
                raise ValueError(f"Signs.{name} must be 1 or -1, not {value!r}")


class GimbalLink:
    """The attitude push in, speed setpoints out, for one open ``GimbalClient``.

    ``start`` subscribes to the push, enables it and starts the speed keep-alive; ``stop`` sends
    zero speed and releases control. Push callbacks run on the client's receive thread and only
    append to the history.
    """

    def __init__(self, client: GimbalClient, *, rate_hz: float = 25.0, signs: Signs = Signs(),
                 history: AttitudeHistory | None = None, bus_timeout: float = DEFAULT_TIMEOUT_S) -> None:
        self.client = client
        self.rate_hz = rate_hz
        self.bus_timeout = bus_timeout
        self.signs = signs
        self.history = history if history is not None else AttitudeHistory()
        self._streamer: SpeedStreamer | None = None
        self._paused: list[SpeedStreamer] = []  # keep-alives stopped by ``pause``: their counts stay

    def start(self, wait_s: float | None = None) -> None:
        """Record the attitude push and enable it (``wait_s``: wait that long for the first one,
        ``GimbalTimeoutError`` after), then start the speed keep-alive."""
        self.client.on_push(ParameterPush, self.on_push)
        self.client.set_push(True)
        if wait_s is not None:
            self.client.wait_for_push(ParameterPush, wait_s)
        self._streamer = self.client.speed_streamer(rate_hz=self.rate_hz, bus_timeout=self.bus_timeout)

    def on_push(self, msg: ParameterPush, t: float) -> None:
        """Record a push's attitude (degrees, as the push gives it); one without valid angles is skipped."""
        attitude = msg.attitude
        if attitude is not None:
            self.history.add(t, attitude.yaw, attitude.roll, attitude.pitch)

    def attitude_at(self, t: float) -> tuple[float, float] | None:
        """The (yaw, pitch) at time ``t`` in this project's convention (yaw positive to the right,
        pitch up); None before the first push."""
        sample = self.history.at(t)
        if sample is None:
            return None
        return sample.yaw * self.signs.yaw_attitude, sample.pitch * self.signs.pitch_attitude

    def latest(self) -> Attitude | None:
        """The newest attitude as the gimbal reported it (its own signs)."""
        return self.history.latest()

    def send(self, command: Rates, stamp: float | None = None) -> None:
        """Stream ``command``'s yaw/pitch rates in the gimbal's signs; ``stamp``: the capture time
        of the frame behind it (for the latency figures)."""
        if self._streamer is None:
            raise RuntimeError("GimbalLink.send before start()")
        self._streamer.set(command.yaw_dps * self.signs.yaw_speed, command.pitch_dps * self.signs.pitch_speed,
                           stamp=stamp)

    def stop(self) -> None:
        """Zero speed, then release control; nothing when the keep-alive never started."""
        if self._streamer is not None:
            self._streamer.stop()

    def pause(self) -> None:
        """The keep-alive's stop (zero speed, then release): the gimbal holds until ``resume``."""
        if self._streamer is None:
            raise RuntimeError("GimbalLink.pause before start()")
        self._streamer.stop()
        self._paused.append(self._streamer)

    def resume(self) -> None:
        """A new keep-alive after ``pause`` (the old one's counts and latencies are kept)."""
        self._streamer = self.client.speed_streamer(rate_hz=self.rate_hz, bus_timeout=self.bus_timeout)

    def recenter(self) -> None:
        """The protocol's recenter (send it paused: a speed command would take over again)."""
        self.client.recenter()

    def _streamers(self) -> list[SpeedStreamer]:
        """Every keep-alive of the run: those ``pause`` stopped, then the current one."""
        current = self._streamer is not None and all(s is not self._streamer for s in self._paused)
        return [*self._paused, self._streamer] if current else list(self._paused)

    @property
    def started(self) -> bool:
        return self._streamer is not None

    def health(self) -> BusHealth | None:
        """The link's state as the keep-alive's watchdog sees it; None before ``start``."""
        return self._streamer.watchdog.snapshot() if self._streamer is not None else None

    def other_hosts(self) -> OtherHostsSeen:
        """What other hosts sent on the bus to this gimbal so far."""
        return self.client.other_hosts.seen()

    def latencies(self) -> list[float]:
        """Seconds from each setpoint's frame to its first send on the bus."""
        return [latency for streamer in self._streamers() for latency in streamer.latencies()]

    def stats(self) -> Mapping[str, int]:
        """The keep-alive's counts and the client's safety-stop counts."""
        summed: Counter[str] = Counter()
        for streamer in self._streamers():
            summed.update(streamer.stats)
        counts = dict(summed)
        counts.update({k: v for k, v in self.client.stats.items() if k.startswith("stop_")})
        return counts
