"""Device pushes (parameter push, calibration status): latest value, callbacks and waiting."""
from __future__ import annotations

import logging
import threading
import time
from collections import Counter
from collections.abc import Callable
from typing import TypeVar

from gimbal.errors import GimbalError, GimbalTimeoutError
from gimbal.messages import Kind, Message, Sender, decode_message, is_device_push
from gimbal.packet import Packet
from gimbal.packet_listener import PacketListener
from gimbal.transport import HOST_RX_ID

log = logging.getLogger(__name__)

M = TypeVar("M", bound=Message)
PushCallback = Callable[[M, float], None]


class CallbackExit(GimbalError):
    """A subscriber raised SystemExit (or another exception that is not an ``Exception``): the
    thread delivering pushes ends with this."""


def _check_push_class(cls: type[Message]) -> None:
    if getattr(cls, "KIND", None) is not Kind.PUSH or getattr(cls, "SENDER", None) is not Sender.DEVICE:
        raise ValueError(f"{getattr(cls, '__name__', cls)!r} is not a push the gimbal sends "
                         "(e.g. ParameterPush, CalibrationStatusPush)")


class PushHub(PacketListener):
    """A ``can.Listener`` that decodes the device pushes among the frames on ``rx_id``, keeps the
    latest of each class with its arrival time (``time.monotonic()``) and calls subscribers.
    A subscriber that raises an ``Exception`` is logged and stays subscribed; one that raises
    SystemExit ends the delivering thread (``CallbackExit``). ``stats`` counts ``pushes`` and
    undecodable ones (``bad_pushes``)."""

    def __init__(self, rx_id: int = HOST_RX_ID, stats: Counter[str] | None = None) -> None:
        super().__init__(rx_id)
        self.stats: Counter[str] = Counter() if stats is None else stats
        self._cond = threading.Condition()
        self._latest: dict[type[Message], tuple[Message, float]] = {}
        self._counts: Counter[type[Message]] = Counter()
        self._callbacks: dict[type[Message], list[PushCallback]] = {}
        self._interrupted: BaseException | None = None

    def subscribe(self, cls: type[M], callback: PushCallback[M]) -> Callable[[], None]:
        """Call ``callback(msg, t)`` for every ``cls`` push; returns a function that unsubscribes."""
        _check_push_class(cls)
        with self._cond:
            self._callbacks.setdefault(cls, []).append(callback)

        def unsubscribe() -> None:
            with self._cond:
                callbacks = self._callbacks.get(cls, [])
                if callback in callbacks:
                    callbacks.remove(callback)
        return unsubscribe

    def on_packet(self, packet: Packet, t: float) -> None:
        if not is_device_push(packet) or self._interrupted is not None:
            return  # the reply matcher's, or after the end (a lost bus: the Notifier runs on until close)
        try:
            message = decode_message(packet)
        except GimbalError as exc:
            self.stats["bad_pushes"] += 1
            log.warning("undecodable push: %s", exc)
            return
        self.stats["pushes"] += 1
        self.deliver(message, t)

    def deliver(self, message: Message, t: float) -> None:
        """Record one push and run its subscribers (on the caller's thread)."""
        cls = type(message)
        with self._cond:
            self._latest[cls] = (message, t)
            self._counts[cls] += 1
            callbacks = list(self._callbacks.get(cls, ()))
            self._cond.notify_all()
        for callback in callbacks:
            try:
                callback(message, t)
            except Exception:  # a user's bug must not stop the receive thread
                log.exception("push callback %r failed on %s", callback, message.NAME)
            except BaseException as exc:  # sys.exit(): it ends this thread, as in any thread
                raise CallbackExit(f"push callback {callback!r} raised {exc!r} on {message.NAME}") from exc

    def latest(self, cls: type[M]) -> tuple[M, float] | None:
        """The newest ``cls`` push and its arrival time, or None if none arrived yet."""
        _check_push_class(cls)
        with self._cond:
            return self._latest.get(cls)  # type: ignore[return-value]

    def interrupt(self, error: BaseException) -> None:
        """No more pushes will come (the client closed or lost the bus): ``wait`` raises ``error``,
        now and from then on."""
        with self._cond:
            self._interrupted = error
            self._cond.notify_all()

    def wait(self, cls: type[M], timeout: float) -> tuple[M, float]:
        """The next ``cls`` push to arrive after this call; ``GimbalTimeoutError`` after ``timeout``
        s, or the error given to ``interrupt``."""
        _check_push_class(cls)
        deadline = time.monotonic() + timeout
        with self._cond:
            seen = self._counts[cls]
            while self._counts[cls] == seen:
                if self._interrupted is not None:
                    raise self._interrupted
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise GimbalTimeoutError(f"no {cls.NAME} within {timeout:g} s")
                self._cond.wait(remaining)
            return self._latest[cls]  # type: ignore[return-value]
