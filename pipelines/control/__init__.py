"""Closed-loop control: camera model, attitude history, direction filter, PID, rate controllers."""
from pipelines.control.attitude import Attitude, AttitudeHistory
from pipelines.control.camera import CameraModel
from pipelines.control.controller import (
    ControlConfig, Controller, ProportionalController, RateCommand, RateController,
    controller_names, make_controller,
)
from pipelines.control.direction import Direction, DirectionFilter, compose, relative, wrap_deg
from pipelines.control.pid import Pid

__all__ = [
    "Attitude", "AttitudeHistory", "CameraModel", "ControlConfig", "Controller", "Direction",
    "DirectionFilter", "Pid", "ProportionalController", "RateCommand", "RateController",
    "compose", "controller_names", "make_controller", "relative", "wrap_deg",
]
