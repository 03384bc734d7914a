"""The gimbal link as a run shows it: one stderr line per episode (replies missing, the gimbal
released, taken back, another controller seen), the camera's record state restored when the
gimbal is taken back, and the report line and exit status at the end. Fed the watchdog's
``BusHealth`` and the client's ``OtherHostsSeen`` on the loop's thread, frame by frame."""
from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from gimbal.watchdog import DISENGAGED

if TYPE_CHECKING:
    from gimbal.other_hosts import OtherHostsSeen
    from gimbal.watchdog import BusHealth
    from pipelines.loop.record import FrameRecord
    from pipelines.loop.recording import Recorder
    from pipelines.sources import Frame


class LinkNotices:
    """Says what changed on the link, once per episode, through ``say`` (one line each)."""

    def __init__(self, timeout_s: float, say: Callable[[str], None]) -> None:
        self.timeout_s = timeout_s
        self._say = say
        self._episodes = 0
        self._disengagements = 0
        self._state: str | None = None
        self._other_control = 0

    def update(self, health: BusHealth, other: OtherHostsSeen, frame: int) -> bool:
        """Say what is new since the last call; True when the gimbal was just taken back."""
        taken_back = self._state == DISENGAGED and health.state != DISENGAGED
        if health.episodes > self._episodes:
            self._say(f"frame {frame}: the gimbal's replies are missing ({health.timeouts - health.late} speed "
                      "commands without a reply so far); tracking and streaming go on")
        if health.disengagements > self._disengagements:
            self._say(f"frame {frame}: no reply for {self.timeout_s:g} s: the gimbal is stopped and released; "
                      "tracking and the outputs go on, and control is taken back when it answers")
        if taken_back:
            self._say(f"frame {frame}: the gimbal answers again: speed control taken back")
        if other.control and not self._other_control:
            self._say(f"frame {frame}: another host is driving this gimbal too ({other.describe()}): "
                      "two controllers fight over it")
        self._episodes, self._disengagements = health.episodes, health.disengagements
        self._state, self._other_control = health.state, other.control
        return taken_back


class LinkSink:
    """A loop sink: the notices for each frame's link state, and the camera's record state restored
    once the gimbal is taken back (it may have been power-cycled meanwhile)."""

    name = "gimbal link"

    def __init__(self, notices: LinkNotices, recorder: Recorder | None = None) -> None:
        self.notices = notices
        self.recorder = recorder

    def on_frame(self, record: FrameRecord, frame: Frame) -> None:
        if record.bus is None or record.other_hosts is None:
            return
        if self.notices.update(record.bus, record.other_hosts, record.index) and self.recorder is not None:
            self.recorder.restore()

    def close(self) -> None:
        """Nothing to finalise: the summary carries the link's figures."""


def link_health(health: BusHealth | None, other: OtherHostsSeen) -> dict[str, Any]:
    """The summary's ``bus_health``: the watchdog's snapshot and what other hosts sent."""
    fields: dict[str, Any] = health.as_dict() if health is not None else {}
    fields["other_hosts"] = {"commands": other.commands, "control": other.control, "names": other.names}
    return fields


def link_degraded(bus_health: Mapping[str, Any]) -> bool:
    """Whether the link left ``engaged`` or another controller was seen (exit status 3)."""
    return bool(bus_health.get("episodes") or bus_health["other_hosts"]["control"])


def link_report(bus_health: Mapping[str, Any], sent: int) -> str:
    """The report's line on the link, e.g. 'gimbal link: degraded (1 episode, released once):
    unreachable 5.1 s, 130 of 400 speed commands unanswered'."""
    other = bus_health["other_hosts"]
    foreign = f"; another host sent {', '.join(f'{n} {k}' for k, n in other['names'].items())}" \
        if other["commands"] else ""
    if "episodes" not in bus_health:
        return f"gimbal link: not started{foreign}"
    unanswered, late = bus_health["unanswered"], bus_health["late"]
    slow = f", {late} answered late" if late else ""
    if not bus_health["episodes"]:
        return f"gimbal link: clean, {unanswered} of {sent} speed commands unanswered{slow}{foreign}"
    episodes = bus_health["episodes"]
    released = bus_health["disengagements"]
    how = f"{episodes} episode{'s' if episodes != 1 else ''}" + \
        (f", released {released} time{'s' if released != 1 else ''}" if released else "")
    return (f"gimbal link: degraded ({how}): unreachable {bus_health['unreachable_s']:.1f} s, "
            f"{unanswered} of {sent} speed commands unanswered{slow}{foreign}")
