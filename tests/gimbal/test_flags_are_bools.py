"""On/off arguments take True or False (numpy's too), not any value Python would call true: the
string "no" turned the parameter push on and took speed control."""
from __future__ import annotations

import numpy as np
import pytest

from gimbal.client import SPEED_HOLD, SPEED_RELEASE, GimbalClient, speed_message
from gimbal.messages.telemetry import PUSH_DISABLE, PushControl
from tests.gimbal.scripted_peer import ScriptedPeer


@pytest.mark.parametrize("value", ["no", "", None, 1, 0.0])
def test_anything_but_a_bool_is_refused_before_sending(value: object, channel: str, peer: ScriptedPeer) -> None:
    peer.answer(PushControl)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        with pytest.raises(TypeError, match=r"^enabled must be True or False, not "):
            client.set_push(value)  # type: ignore[arg-type]
        with pytest.raises(TypeError, match=r"^start must be True or False, not "):
            client.auto_calibration(value)  # type: ignore[arg-type]
    assert peer.messages(PushControl) == []
    with pytest.raises(TypeError, match=r"^take_control must be True or False, not "):
        speed_message(1.0, 0.0, take_control=value)  # type: ignore[arg-type]


def test_numpy_bools_are_taken(channel: str, peer: ScriptedPeer) -> None:
    peer.answer(PushControl)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        client.set_push(np.bool_(False))
    assert [m.ctrl_byte for m in peer.messages(PushControl)] == [PUSH_DISABLE]
    assert speed_message(1.0, 0.0, take_control=np.bool_(True)).ctrl_byte == SPEED_HOLD
    assert speed_message(1.0, 0.0, take_control=np.bool_(False)).ctrl_byte == SPEED_RELEASE
