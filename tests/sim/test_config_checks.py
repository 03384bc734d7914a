"""``SimConfig`` and ``Faults`` refuse every non-finite or out-of-range value with a ValueError
naming the field: a NaN delay once queued every reply for ever, a NaN base yaw killed the tick
thread at the first parameter push, while the process carried on."""
from __future__ import annotations

import math

import numpy as np
import pytest

from gimbal.sim import Faults, SimConfig, start_in_process
from gimbal.sim.checks import FieldError


NAN, INF = math.nan, math.inf


@pytest.mark.parametrize("field, value", [
    ("base_yaw_deg", NAN), ("base_yaw_deg", INF), ("push_rate_hz", INF), ("accel_dps2", NAN),
    ("max_speed_dps", INF), ("speed_timeout_s", INF), ("calibration_s", NAN), ("calibration_s", -1.0),
    ("focus_calibration_s", INF), ("initial_joint_deg", (0.0, NAN, 0.0)), ("initial_joint_deg", (0.0, 0.0)),
    ("rx_id", 0x800), ("tx_id", -1), ("device_id", 0), ("version", 1 << 32), ("speed_signs", (1, 0, 1)),
    # 1e300 Hz once pushed ~10,000 times a second: 50,000 frames, several times what the bus carries
    ("push_rate_hz", 1e300), ("push_rate_hz", 1000.5), ("calibration_push_hz", 1e300),
    ("legacy", "no"), ("yaw_continuous", 1), ("camera_connected", None),  # "no" once meant legacy firmware
    ("tx_id", 0x223),  # the default rx_id
])
def test_sim_config_refuses(field: str, value: object) -> None:
    with pytest.raises(FieldError, match=rf"^SimConfig\.{field} takes .*, not ") as caught:
        SimConfig(**{field: value})
    assert caught.value.name == f"SimConfig.{field}"


@pytest.mark.parametrize("field, value", [
    ("delay_s", NAN), ("delay_s", INF), ("delay_s", -0.001), ("drop", NAN), ("nack", 1.5),
    ("legacy", -0.1), ("foreign_rate", NAN), ("nack_code", 0x100), ("nack_code", 0), ("direction", "up"),
    ("silent", (NAN, 1.0)), ("silent", (1.0, NAN)), ("silent", (INF, INF)), ("silent", (3.0, 1.0)),
])
def test_faults_refuse(field: str, value: object) -> None:
    with pytest.raises(ValueError, match=rf"^Faults\.{field} takes .*, not "):
        Faults(**{field: value})


def test_the_edges_are_taken() -> None:
    SimConfig(calibration_s=0.0, base_yaw_deg=-720.0, rx_id=0x7FF, tx_id=0, version=0xFFFFFFFF,
              push_rate_hz=1000.0, calibration_push_hz=1000.0)
    Faults(drop=1.0, delay_s=0.0, nack_code=0xFF, foreign_rate=20_000, silent=(5.0, INF))  # silent to the end


def test_numpy_numbers_are_taken_and_answered(make_client) -> None:
    """Values read from a numpy array (a config file, a sweep) pass the checks as Python's do."""
    client, _ = make_client(SimConfig(version=np.uint32(0x01020304), device_id=np.int64(1), rx_id=np.int32(0x223),
                                      tx_id=np.int16(0x222), push_rate_hz=np.float32(50.0), legacy=np.False_),
                            Faults(nack_code=np.uint8(3), delay_s=np.float64(0.0)))
    reply = client.version()
    assert (reply.device_id, reply.version_text) == (1, "01.02.03.04")


# A stopped simulated gimbal says it cannot be started again (it said "already started").
def test_start_after_stop_names_the_stop() -> None:
    host_bus, sim = start_in_process()
    try:
        with pytest.raises(RuntimeError, match="already started"):
            sim.start()
        sim.stop()
        with pytest.raises(RuntimeError, match="stopped simulated gimbal cannot be started again"):
            sim.start()
    finally:
        sim.stop()
        host_bus.shutdown()
