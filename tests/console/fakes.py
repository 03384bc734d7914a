"""A fake loop for the console's HTTP tests: an operator that records what it was asked, and a
thread that hands the sink synthetic frames at a steady rate and counts them."""
from __future__ import annotations

import threading
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Self

import numpy as np

from pipelines.console import (
    ConsoleServer,
    ConsoleSink,
    ConsoleView,
    parse_console_address,
)

SIZE = (640, 360)
IMAGES = 77  # the bar crosses the frame once in these many frames


def view(index: int, t: float) -> ConsoleView:
    return ConsoleView(index, t, "tracking", (100.0, 80.0, 40.0, 60.0), 0.9, (1.5, -0.5),
                       ((300.0, 100.0, 50.0, 50.0),))


@dataclass
class FakeOperator:
    calls: list[tuple[str, Any]] = field(default_factory=list)
    refuse_settings: str | None = None

    def select(self, box): self.calls.append(("select", box))
    def pause(self): self.calls.append(("pause", None))
    def resume(self): self.calls.append(("resume", None))
    def recenter(self): self.calls.append(("recenter", None))
    def set_recording(self, on): self.calls.append(("record", on))
    def stop(self): self.calls.append(("stop", None))

    def apply_settings(self, changes: Mapping[str, float]) -> None:
        if self.refuse_settings:
            raise ValueError(self.refuse_settings)
        self.calls.append(("settings", dict(changes)))

    def frame_size(self): return SIZE

    def state(self) -> dict[str, Any]:
        return {"source": "synthetic", "fps": 30.0, "paused": False, "recording": {"on": False},
                "latency_ms": {"p50": 5.0, "p99": 9.0}, "bus": {"timeouts": 0, "nacks": 0, "silent": False},
                "settings": {"max_speed": 120.0}}


def synthetic_image(index: int, noisy: bool = False) -> np.ndarray:
    """A frame that changes every time: a bright bar moving across a gradient; ``noisy``: over
    noise instead, which JPEG cannot shrink much (parts of a camera frame's size, ~100 kB)."""
    width, height = SIZE
    if noisy:
        image = np.random.default_rng(index).integers(0, 120, (height, width, 3), dtype=np.uint8)
    else:
        image = np.tile(np.linspace(0, 120, width, dtype=np.uint8)[None, :, None], (height, 1, 3))
    x = (index * 8) % (width - 20)
    image[:, x:x + 20] = 255
    return image


class FrameFeeder:
    """Calls ``sink.on_frame`` at up to ``fps`` from its own thread (the loop's stand-in);
    ``fps=None`` as fast as it can. ``rate()`` is the frames per second it achieved."""

    def __init__(self, sink: ConsoleSink, fps: float | None = 30.0, work_s: float = 0.0,
                 noisy: bool = False) -> None:
        self.sink, self.fps, self.work_s = sink, fps, work_s
        self.frames = 0
        self.hand_over_s: list[float] = []  # each on_frame call's duration
        self.error: BaseException | None = None
        self._stop = threading.Event()
        self._images = [synthetic_image(i, noisy) for i in range(IMAGES)]
        self._thread = threading.Thread(target=self._run, daemon=True)
        self.started = self.ended = 0.0

    def __enter__(self) -> Self:
        self.started = time.monotonic()
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()

    def _run(self) -> None:
        next_t = time.monotonic()
        try:
            while not self._stop.is_set():
                if self.work_s:  # the loop's own work, CPU-bound like tracking
                    end = time.perf_counter() + self.work_s
                    while time.perf_counter() < end:
                        pass
                index = self.frames
                handed = time.perf_counter()
                self.sink.on_frame(view(index, time.monotonic()), self._images[index % len(self._images)])
                self.hand_over_s.append(time.perf_counter() - handed)
                self.frames += 1
                self.ended = time.monotonic()
                if self.fps:
                    next_t += 1.0 / self.fps
                    self._stop.wait(max(0.0, next_t - time.monotonic()))
        except BaseException as exc:  # noqa: BLE001 (the test reads it)
            self.error = exc

    def rate(self) -> float:
        return self.frames / max(1e-9, self.ended - self.started)


def start_console(operator: FakeOperator | None = None, address: str = "127.0.0.1:0",
                  token: str | None = None, **kwargs: Any) -> tuple[ConsoleServer, ConsoleSink, FakeOperator]:
    operator = operator or FakeOperator()
    sink = ConsoleSink(dead_zone_px=lambda: 6.0)
    server = ConsoleServer(operator, sink, parse_console_address(address), token=token, **kwargs)
    server.start()
    return server, sink, operator
