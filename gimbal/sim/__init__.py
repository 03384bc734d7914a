"""A protocol-complete simulated DJI RS gimbal: the device side of the R SDK over any python-can
bus, with an axis model and fault injection (see docs/simulator.md)."""
from __future__ import annotations

from gimbal.sim.config import SimConfig
from gimbal.sim.device import SimulatedGimbal, start_in_process
from gimbal.sim.faults import Faults
from gimbal.sim.state import SimState

__all__ = ["Faults", "SimConfig", "SimState", "SimulatedGimbal", "start_in_process"]
