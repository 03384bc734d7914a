"""The first things every client needs: angles, position, speed, push, camera."""
from __future__ import annotations

import time

from gimbal.messages import camera, motion, telemetry

from tests.sim.helpers import wait_until


def test_get_angles_attitude_and_joint_with_base_yaw(make_sim) -> None:
    from gimbal.sim import SimConfig
    host, sim, _ = make_sim(SimConfig(base_yaw_deg=90.0, initial_joint_deg=(10.0, 2.0, -5.0)))
    attitude = host.ask(motion.GetAngles(motion.ANGLES_ATTITUDE))
    joint = host.ask(motion.GetAngles(motion.ANGLES_JOINT))
    assert (attitude.return_code, attitude.data_type) == (0, 1)
    assert (attitude.yaw, attitude.roll, attitude.pitch) == (1000, 20, -50)
    assert (joint.data_type, joint.yaw, joint.roll, joint.pitch) == (2, 100, 20, -50)


def test_position_moves_uniformly_in_time_for_action(sim_host) -> None:
    host, sim = sim_host
    start = time.monotonic()
    reply = host.ask(motion.PositionControl(300, 0, -200, motion.POSITION_ABSOLUTE, 10))
    assert reply.ok
    time.sleep(0.5)
    halfway = sim.state().joint
    assert 11.0 < halfway[0] < 19.0 and -12.5 < halfway[2] < -7.5
    assert wait_until(lambda: not sim.state().moving, 1.5)
    assert 0.95 < time.monotonic() - start < 1.3
    assert sim.state().joint == (30.0, 0.0, -20.0)


def test_speed_moves_then_stops(sim_host) -> None:
    host, sim = sim_host
    assert host.ask(motion.SpeedControl(200, 0, -100, 0x88)).ok
    time.sleep(0.25)
    state = sim.state()
    assert state.speeds[0] == 20.0 and state.speeds[2] == -10.0 and state.speed_control
    assert wait_until(lambda: not sim.state().moving, 1.0)
    yaw, _, pitch = sim.state().joint
    assert 9.5 < yaw < 10.5 and -5.25 < pitch < -4.75


def test_parameter_push_after_enable(sim_host) -> None:
    host, sim = sim_host
    assert host.collect(0.2) == []
    assert host.ask(telemetry.PushControl(telemetry.PUSH_ENABLE)).ok
    pushes = [m for m, _ in host.collect(0.5) if isinstance(m, telemetry.ParameterPush)]
    assert 20 <= len(pushes) <= 30
    assert pushes[-1].angles_valid and pushes[-1].limits_valid and pushes[-1].stiffness_valid
    assert host.ask(telemetry.PushControl(telemetry.PUSH_DISABLE)).ok
    host.collect(0.05)
    assert host.collect(0.2) == []


def test_record_state_round_trips(sim_host) -> None:
    host, sim = sim_host
    assert host.ask(camera.CameraStatusQuery()).camera_status == camera.NOT_RECORDING
    assert host.ask(camera.CameraAction(camera.CameraActionCode.START_RECORDING)).ok
    assert host.ask(camera.CameraStatusQuery()).recording is True
    assert sim.state().recording
    assert host.ask(camera.CameraAction(camera.CameraActionCode.STOP_RECORDING)).ok
    assert host.ask(camera.CameraStatusQuery()).recording is False
