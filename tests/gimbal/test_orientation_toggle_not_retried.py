"""Orientation 0x05 (section 2.3.4.14, Figure 26) swaps landscape and portrait: sent twice it
swaps back, so an unanswered toggle is never resent, while the absolute orientations are."""
from __future__ import annotations

from collections.abc import Iterator

import pytest

from gimbal.client import GimbalClient
from gimbal.errors import GimbalTimeoutError
from gimbal.messages.settings import SetWorkMode
from tests.gimbal.scripted_peer import ScriptedPeer


@pytest.fixture
def client(channel: str, peer: ScriptedPeer) -> Iterator[GimbalClient]:
    with GimbalClient(interface="virtual", channel=channel, timeout=0.05, retries=1) as gimbal:
        yield gimbal


@pytest.mark.parametrize("orientation,sends", [("toggle", 1), ("portrait", 2)])
def test_only_the_toggle_goes_out_once(client: GimbalClient, peer: ScriptedPeer,
                                       orientation: str, sends: int) -> None:
    peer.silence(SetWorkMode)
    with pytest.raises(GimbalTimeoutError):
        client.set_work_mode(orientation)
    assert len(peer.wait_for(SetWorkMode, sends)) == sends
