"""Which command a latest-layout reply names: CmdSet and CmdID are its first two DATA bytes
(section 2.2, Figure 3), however little follows them."""
from __future__ import annotations

import pytest

from gimbal.errors import PayloadError
from gimbal.messages import decode_message, reply_key
from gimbal.packet import REPLY_CMD_TYPE, Packet


def test_cmdset_and_cmdid_alone_name_the_command() -> None:
    """Two DATA bytes are enough to pair the reply; the missing return code fails only decoding."""
    packet = Packet(REPLY_CMD_TYPE, 1, b"\x0e\x01")
    assert reply_key(packet) == (0x0E, 0x01)
    with pytest.raises(PayloadError):
        decode_message(packet)


def test_one_byte_cannot_name_a_command() -> None:
    with pytest.raises(PayloadError):
        reply_key(Packet(REPLY_CMD_TYPE, 1, b"\x0e"))
