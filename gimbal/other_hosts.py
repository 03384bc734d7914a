"""Another controller on the bus: commands on our transmit id that this client did not send.

A bus does not hand a sender its own frames (and the loopback of udp_multicast is recognised by
the transport), so every packet reassembled from frames on the host's transmit id comes from
another host. Two controllers streaming speeds to one gimbal fight: its yaw speed flips between
their setpoints. ``OtherHosts`` is a ``can.Listener`` with no I/O, fed those frames by the client's
``can.Notifier`` (or by a test); queries (angles, version, camera status) are counted but are no
conflict, since a monitoring tool may send them.
"""
from __future__ import annotations

import threading
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field

from gimbal.errors import PayloadError
from gimbal.messages import decode_message
from gimbal.messages.external import DialPush, JoystickPush
from gimbal.messages.motion import PositionControl, SpeedControl
from gimbal.messages.settings import ActiveTrack, RecenterSelfie
from gimbal.packet import Packet
from gimbal.packet_listener import PacketListener
from gimbal.transport import HOST_TX_ID

#: Commands that move the gimbal or take it over: another host sending one is another controller.
CONTROL_COMMANDS = (SpeedControl, PositionControl, RecenterSelfie, JoystickPush, DialPush, ActiveTrack)
UNDECODED = "undecoded"


@dataclass(frozen=True)
class OtherHostsSeen:
    """What other hosts sent on our transmit id: ``commands`` in all, ``control`` of them moving
    the gimbal or taking it over, by message name in ``names``; ``first_control``: when the first
    of those came (the listener's clock), None if none did."""

    commands: int = 0
    control: int = 0
    first_control: float | None = None
    names: dict[str, int] = field(default_factory=dict)

    def describe(self) -> str:
        """e.g. '12 speed_control, 1 get_angles'."""
        return ", ".join(f"{count} {name}" for name, count in sorted(self.names.items(), key=lambda kv: -kv[1]))


class OtherHosts(PacketListener):
    """Counts the packets another host sends on ``tx_id``; ``wait_for_control`` for a newcomer's
    short listen before it takes control."""

    def __init__(self, tx_id: int = HOST_TX_ID, clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__(tx_id)
        self._clock = clock
        self._lock = threading.Lock()
        self._names: Counter[str] = Counter()
        self._commands = 0
        self._control = 0
        self._first_control: float | None = None
        self._controlled = threading.Event()

    def on_packet(self, packet: Packet, t: float) -> None:
        if packet.is_reply:
            return  # a gimbal answering on the host's id is not a controller
        try:
            message = decode_message(packet)
            name, control = message.NAME, isinstance(message, CONTROL_COMMANDS)
        except PayloadError:
            name, control = UNDECODED, False
        with self._lock:
            self._commands += 1
            self._names[name] += 1
            if control:
                self._control += 1
                if self._first_control is None:
                    self._first_control = self._clock()
        if control:
            self._controlled.set()

    def seen(self) -> OtherHostsSeen:
        with self._lock:
            return OtherHostsSeen(self._commands, self._control, self._first_control, dict(self._names))

    def wait_for_control(self, timeout: float) -> bool:
        """Whether another host sent a control command, within ``timeout`` s from now at the latest."""
        return self._controlled.wait(timeout)
