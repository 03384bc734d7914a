"""Closed-loop control: camera model, attitude history, direction filter, PID, rate controllers.

The names below are loaded on first use (module ``__getattr__``): importing the package, or one
light module of it such as ``limits``, does not load the controllers' numpy and filterpy."""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

_HOMES = {
    "Attitude": "attitude", "AttitudeHistory": "attitude", "CameraModel": "camera",
    "ControlConfig": "controller", "Controller": "controller", "ProportionalController": "controller",
    "RateCommand": "controller", "RateController": "controller", "controller_names": "controller",
    "make_controller": "controller", "Direction": "direction", "DirectionFilter": "direction",
    "compose": "direction", "relative": "direction", "wrap_deg": "direction", "Pid": "pid",
}
__all__ = sorted(_HOMES)

if TYPE_CHECKING:
    from pipelines.control.attitude import Attitude, AttitudeHistory
    from pipelines.control.camera import CameraModel
    from pipelines.control.controller import (
        ControlConfig, Controller, ProportionalController, RateCommand, RateController,
        controller_names, make_controller,
    )
    from pipelines.control.direction import Direction, DirectionFilter, compose, relative, wrap_deg
    from pipelines.control.pid import Pid


def __getattr__(name: str) -> Any:
    if name not in _HOMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_HOMES[name]}"), name)
    globals()[name] = value
    return value
