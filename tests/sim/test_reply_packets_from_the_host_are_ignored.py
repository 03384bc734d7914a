"""Packets with the reply bit set that reach the simulator are ignored and counted, never executed."""
from __future__ import annotations

import time

from gimbal.messages import camera
from gimbal.packet import Packet


def test_a_reply_shaped_camera_action_is_not_executed(sim_host) -> None:  # type: ignore[no-untyped-def]
    """A "start recording" payload sent with the reply bit: no reply, not recording, counted."""
    host, sim = sim_host
    payload = int(camera.CameraActionCode.START_RECORDING).to_bytes(2, "little")
    host.transport.send(Packet.reply(0x0D, 0x00, payload, 7))
    assert host.transport.recv(0.15) is None
    time.sleep(0.02)
    state = sim.state()
    assert not state.recording and state.commands.get("camera_action", 0) == 0
    assert state.faults["replies_received"] == 1
