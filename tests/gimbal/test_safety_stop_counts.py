"""The safety stop's two speed commands (zero in control, then zero with bit 7 clear: section
2.3.4.2, Figure 8) are counted apart in ``GimbalClient.stats``."""
from __future__ import annotations

import pytest

from gimbal.client import GimbalClient
from gimbal.errors import GimbalTimeoutError, ReturnCodeError
from gimbal.messages.motion import SpeedControl
from tests.gimbal.scripted_peer import RELEASE, ZERO, ScriptedPeer, speed_messages


def test_the_zero_and_the_release_are_counted_each_once(channel: str, peer: ScriptedPeer) -> None:
    peer.answer(SpeedControl)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        client.speed(10, 0)
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    assert (client.stats["stop_zero_sent"], client.stats["stop_release_sent"]) == (1, 1)


def test_a_stop_the_gimbal_leaves_unanswered_is_still_counted_as_sent(channel: str, peer: ScriptedPeer) -> None:
    """A gimbal gone silent (the track summary after "no reply to 10 consecutive speed commands"):
    the two stops go out and are in the CAN log, so the counts say they were sent, not nothing."""
    peer.silence(SpeedControl)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.05, retries=0) as client:
        with pytest.raises(GimbalTimeoutError):
            client.speed(10, 0)
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    assert (client.stats["stop_zero_sent"], client.stats["stop_release_sent"]) == (1, 1)


def test_a_stop_the_gimbal_refuses_is_still_counted_as_sent(channel: str, peer: ScriptedPeer) -> None:
    peer.nack(SpeedControl, 0x02)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        with pytest.raises(ReturnCodeError):
            client.speed(10, 0)
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    assert (client.stats["stop_zero_sent"], client.stats["stop_release_sent"]) == (1, 1)
