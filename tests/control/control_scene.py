"""A synthetic closed loop for the control tests: a rate-driven gimbal plant and a moving subject."""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from pipelines.control.camera import CameraModel
from pipelines.control.controller import Controller
from pipelines.control.direction import relative, wrap_deg
from tracker.runtime.estimate import TargetEstimate, TrackState

PLANT_STEP = 0.001
Subject = Callable[[float], tuple[float, float]]  # time -> world (yaw, pitch), degrees


class Plant:
    """Integrates commanded yaw/pitch rates through a pure delay and a first-order lag."""

    def __init__(self, tau: float = 0.05, delay: float = 0.0) -> None:
        self.tau, self.delay = tau, delay
        self.t = 0.0
        self.yaw = self.pitch = 0.0
        self.rate = [0.0, 0.0]
        self._pending: deque[tuple[float, float, float]] = deque()
        self._target = (0.0, 0.0)

    def command(self, yaw_dps: float, pitch_dps: float) -> None:
        self._pending.append((self.t + self.delay, yaw_dps, pitch_dps))

    def advance(self, t_end: float) -> None:
        while self.t < t_end - 1e-12:
            while self._pending and self._pending[0][0] <= self.t:
                _, y, p = self._pending.popleft()
                self._target = (y, p)
            k = PLANT_STEP / (self.tau + PLANT_STEP)
            self.rate = [r + k * (c - r) for r, c in zip(self.rate, self._target)]
            self.yaw = wrap_deg(self.yaw + self.rate[0] * PLANT_STEP)
            self.pitch += self.rate[1] * PLANT_STEP
            self.t += PLANT_STEP


@dataclass
class Trace:
    t: list[float] = field(default_factory=list)
    err: list[float] = field(default_factory=list)  # angle subject-to-axis, degrees
    yaw_err: list[float] = field(default_factory=list)
    cmd_t: list[float] = field(default_factory=list)
    cmd_yaw: list[float] = field(default_factory=list)
    cmd_pitch: list[float] = field(default_factory=list)
    cmd_roll: list[float] = field(default_factory=list)
    mode: list[str] = field(default_factory=list)
    gimbal_rate: list[float] = field(default_factory=list)

    def arr(self, name: str) -> np.ndarray:
        return np.asarray(getattr(self, name))

    def window(self, name: str, t0: float, t1: float = math.inf) -> np.ndarray:
        t = self.arr("cmd_t" if name.startswith("cmd") or name == "mode" else "t")
        return self.arr(name)[(t >= t0) & (t < t1)]


def run_scene(controller: Controller, subject: Subject, duration: float, *,
              camera: CameraModel | None = None, latency: float = 0.0, plant_delay: float = 0.0,
              tau: float = 0.05, frame_dt: float = 1 / 30, hidden: Callable[[float], bool] = lambda t: False,
              noise_px: float = 0.0, seed: int = 0) -> Trace:
    """Run the loop: frame captured at t, estimate handed to the controller at t + latency
    together with the exact attitude at t; its setpoint goes to the plant at once."""
    camera = camera or CameraModel(640, 360)
    rng = np.random.default_rng(seed)
    plant = Plant(tau, plant_delay)
    trace = Trace()
    pending: deque[tuple[float, TargetEstimate | None, tuple[float, float]]] = deque()
    n = int(duration / frame_dt)
    for i in range(n + int(latency / frame_dt) + 1):
        t = i * frame_dt
        plant.advance(t)
        if i < n:
            sy, sp = subject(t)
            oy, op = relative((plant.yaw, plant.pitch), (sy, sp))
            est = None
            if not hidden(t) and abs(oy) < 89 and abs(op) < 89:
                x, y = camera.angles_to_pixel(oy, op)
                if noise_px:
                    x, y = x + rng.normal(0, noise_px), y + rng.normal(0, noise_px)
                if 0 <= x < camera.width and 0 <= y < camera.height:
                    est = TargetEstimate((x - 10, y - 10, 20, 20), (0.0, 0.0), 0.9, TrackState.TRACKING, t, i)
            pending.append((t + latency, est, (plant.yaw, plant.pitch)))
            err = math.degrees(math.acos(max(-1.0, min(1.0, _cos_between((plant.yaw, plant.pitch), (sy, sp))))))
            trace.t.append(t)
            trace.err.append(err)
            trace.yaw_err.append(wrap_deg(sy - plant.yaw))
            trace.gimbal_rate.append(plant.rate[0])
        while pending and pending[0][0] <= t + 1e-9:
            due, est, att = pending.popleft()
            cmd = controller.update(est, att, due)
            plant.command(cmd.yaw_dps, cmd.pitch_dps)
            trace.cmd_t.append(due)
            trace.cmd_yaw.append(cmd.yaw_dps)
            trace.cmd_pitch.append(cmd.pitch_dps)
            trace.cmd_roll.append(cmd.roll_dps)
            trace.mode.append(cmd.mode)
    return trace


def _cos_between(a: tuple[float, float], b: tuple[float, float]) -> float:
    ya, pa, yb, pb = (math.radians(v) for v in (*a, *b))
    return math.sin(pa) * math.sin(pb) + math.cos(pa) * math.cos(pb) * math.cos(ya - yb)
