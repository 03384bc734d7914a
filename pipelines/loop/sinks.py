"""Where the loop's records go: one sink per output, attached by the command that wants it
(as python-can attaches Listeners to a Notifier). A sink's ``on_frame`` runs on the loop's thread
after every step, in the order the sinks were attached; an exception from it ends the step (and
the later sinks do not see that frame). ``close`` finalises the output."""
from __future__ import annotations

import dataclasses
import math
import time
from collections import Counter
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Protocol, TYPE_CHECKING

from pipelines.loop.record import FrameRecord

if TYPE_CHECKING:
    from pipelines.sources import Frame


class Sink(Protocol):
    """What the loop hands every frame to. ``name`` says which output failed, in one line."""

    name: str

    def on_frame(self, record: FrameRecord, frame: Frame) -> None: ...

    def close(self) -> None: ...


def telemetry_record(record: FrameRecord) -> dict[str, Any]:
    """The telemetry line of a frame (keys as documented in docs/outputs.md)."""
    from pipelines.outputs.telemetry import estimate_fields
    line: dict[str, Any] = {"frame": record.index, "t": record.t, "t_run": record.t_run, "state": record.state}
    if record.t_video is not None:  # where the frame sits in the recording
        line["t_video"] = record.t_video
    if record.estimate is not None:
        line.update(estimate_fields(record.estimate))
    command, attitude, error = record.command, record.attitude, record.error_deg
    line.update({"error_deg": None if error is None else list(error),
                 "rate_dps": [command.yaw_dps, command.pitch_dps], "mode": command.mode,
                 "attitude_deg": None if attitude is None else [attitude.yaw, attitude.pitch, attitude.roll],
                 "attitude_t": None if attitude is None else attitude.timestamp,
                 "dropped": record.dropped})
    line["state"] = record.state  # paused, whatever the tracker says
    if record.operator:
        line["operator"] = list(record.operator)
    if record.bus is not None:
        line["bus"] = record.bus.as_dict()
    if record.other_hosts is not None:
        line["other_hosts"] = record.other_hosts.control
    return line


class TelemetrySink:
    """One JSON line per frame, flushed as written."""

    name = "telemetry"

    def __init__(self, path: Path) -> None:
        from pipelines.outputs.telemetry import TelemetryWriter
        self.writer = TelemetryWriter(path)

    def on_frame(self, record: FrameRecord, frame: Frame) -> None:
        self.writer.write(telemetry_record(record))

    def close(self) -> None:
        self.writer.close()


class VideoSink:
    """The annotated video, labelled with the source's frame index and the recording's time."""

    name = "annotated video"

    def __init__(self, path: Path, size: tuple[int, int], fps: float, width: int | None) -> None:
        from pipelines.outputs.annotated_video import BackgroundVideoWriter
        self.writer = BackgroundVideoWriter(path, size, fps, width)

    def on_frame(self, record: FrameRecord, frame: Frame) -> None:
        from pipelines.outputs.annotated_video import rates_text
        shown_t = record.t_video if record.t_video is not None else record.t_run
        command = record.command
        rates = (command.yaw_dps, command.pitch_dps)
        if record.estimate is not None:
            shown = dataclasses.replace(record.estimate, frame_index=frame.index, timestamp=shown_t)
            self.writer.write(frame.image, shown, rates, [f"mode {command.mode}"])
        else:  # the same three lines, the frame's first
            self.writer.write(frame.image, None, None, [f"#{frame.index} t={shown_t:.3f}s {record.state}",
                                                        rates_text(rates), f"mode {command.mode}"])

    def close(self) -> None:
        self.writer.close()


@dataclasses.dataclass(frozen=True)
class Panel:
    """One panel of a plot: a title, a y label and its series, each a value taken from a record."""

    title: str
    ylabel: str
    series: dict[str, Callable[[FrameRecord], float]]


def _nan(value: float | None) -> float:
    return math.nan if value is None else value


#: What ``gimbaltrack track``'s plot.png shows.
TRACK_PANELS = (
    Panel("angular error (target - pointing)", "deg",
          {"yaw": lambda r: r.command.yaw_error_deg, "pitch": lambda r: r.command.pitch_error_deg}),
    Panel("commanded rates", "deg/s", {"yaw": lambda r: r.command.yaw_dps, "pitch": lambda r: r.command.pitch_dps}),
)


#: How the plot and the summary name a run whose picture cannot answer the gimbal (a recording
#: played against it): the error it shows is not one the gimbal could close.
OPEN_LOOP = "open loop: the picture does not follow the gimbal"
CLOSED_LOOP = "closed loop"


def loop_panels(closed: bool, panels: Sequence[Panel] = TRACK_PANELS) -> tuple[Panel, ...]:
    """``panels`` with the first title saying whether the loop is closed, so that an open loop's
    climbing error is not read as a failure."""
    first = dataclasses.replace(panels[0], title=f"{panels[0].title} - {CLOSED_LOOP if closed else OPEN_LOOP}")
    return (first, *panels[1:])


class PlotSink:
    """Collects the panels' values, one per frame against ``t_run``; ``close`` draws plot.png
    (nothing when no frame came: a run that ended before its first frame has nothing to plot)."""

    name = "plot"

    def __init__(self, path: Path, panels: Sequence[Panel] = TRACK_PANELS) -> None:
        self.path = path
        self.panels = panels
        self.t: list[float] = []
        self.values: list[dict[str, list[float]]] = [{name: [] for name in p.series} for p in panels]

    def on_frame(self, record: FrameRecord, frame: Frame) -> None:
        self.t.append(record.t_run)
        for panel, values in zip(self.panels, self.values):
            for name, value in panel.series.items():
                values[name].append(_nan(value(record)))

    @property
    def written(self) -> bool:
        """Whether ``close`` has something to draw."""
        return bool(self.t)

    def close(self) -> None:
        if not self.t:
            return
        from pipelines.outputs.plot import write_timeseries_png
        write_timeseries_png(self.path, self.t, self.values, titles=[p.title for p in self.panels],
                             ylabels=[p.ylabel for p in self.panels])


class SummarySink:
    """The run's counts as they stand (frames, states, angular error), and the summary rewritten
    through ``write(sync=False)`` at most every ``every_s`` seconds while the run goes. Attach it
    right after the telemetry: a frame is counted once its line is written, whichever later
    output fails, so the summary's ``frames`` are the telemetry's lines."""

    name = "summary"

    def __init__(self, write: Callable[[bool], object], every_s: float = 1.0,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self._write = write
        self.every_s = every_s
        self._clock = clock
        self._last_written = -math.inf
        self.frames = 0
        self.dropped = 0  # what the source had dropped by the last frame (not what it drops after the run)
        self.states: Counter[str] = Counter()
        self.error_frames = 0  # frames whose command had a subject to measure the error against
        self.error_sum = 0.0
        self.error_max: float | None = None

    def on_frame(self, record: FrameRecord, frame: Frame) -> None:
        self.frames += 1
        self.dropped = record.dropped
        self.states[record.state] += 1
        error = record.angular_error_deg
        if error is not None:
            self.error_frames += 1
            self.error_sum += error
            self.error_max = error if self.error_max is None else max(self.error_max, error)
        self.maybe_write()

    def maybe_write(self) -> None:
        """Rewrite the summary if ``every_s`` has passed since the last write."""
        if self._clock() - self._last_written >= self.every_s:
            self.written()
            self._write(False)

    def written(self) -> None:
        """The summary was just written (by this sink or its owner)."""
        self._last_written = self._clock()

    def angular_error(self) -> dict[str, float | int | None]:
        return {"mean": self.error_sum / self.error_frames if self.error_frames else None,
                "max": self.error_max, "frames": self.error_frames}

    def close(self) -> None:
        """Nothing to finalise: the owner writes the final summary, with how the run ended."""


class ProgressSink:
    """The progress line: frames, fps, state and rates."""

    name = "progress"

    def __init__(self, total: int | None, enabled: bool = True) -> None:
        from pipelines.outputs.progress import ProgressReporter
        self.reporter = ProgressReporter(total, enabled=enabled)
        self.frames = 0

    def on_frame(self, record: FrameRecord, frame: Frame) -> None:
        self.frames += 1
        c = record.command
        self.reporter.update(self.frames, lambda: f"{record.state:<9} yaw {c.yaw_dps:+6.1f} "
                                                  f"pitch {c.pitch_dps:+6.1f} deg/s")

    def finish(self, status: str) -> None:
        """The last line, with how the run ended."""
        self.reporter.update(self.frames, status, force=True)

    def close(self) -> None:
        self.reporter.close()
