"""``gimbaltrack decode``: DJI R SDK packets (hex or a CAN log) -> one JSON object per line."""
from __future__ import annotations

import argparse
import binascii
import json
import os
import re
import struct
import sys
import zlib
from collections.abc import Iterable, Iterator
from contextlib import closing
from typing import Any, TextIO

import can

from gimbal.log_decode import GIMBAL_TO_HOST, HOST_TO_GIMBAL, LogDecoder
from gimbal.transport import HOST_RX_ID, HOST_TX_ID
from pipelines.cli.common import CliError, parse_int
from pipelines.cli.firmware_opts import add_legacy_order_option

_DIRECTION_ALIASES = {"host": HOST_TO_GIMBAL, "gimbal": GIMBAL_TO_HOST, HOST_TO_GIMBAL: HOST_TO_GIMBAL,
                      GIMBAL_TO_HOST: GIMBAL_TO_HOST}
_SEPARATORS = re.compile(r"[\s:,]+|0[xX](?=[0-9a-fA-F])")
# How Python words a field that does not parse as a number, as python-can's readers pass it on.
_BAD_NUMBER = re.compile(r"(?:invalid literal for int\(\) with base (?P<base>\d+)|"
                         r"could not convert string to float): (?P<value>.*)")


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "decode", help="decode DJI R SDK packets from hex or a CAN log into JSON lines",
        description="Decode DJI R SDK packets into one JSON object per packet (document field names, "
        "raw wire values). Anything that does not decode is reported with an 'error' key and the raw "
        "bytes. Exits 0 whenever the input could be read, whatever it held.")
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("log", nargs="?", help="CAN log in any format python-can reads "
                        "(candump .log, .asc, .blf, .csv, .trc, .db; .gz of those)")
    source.add_argument("--hex", action="append", metavar="BYTES",
                        help="packet bytes in hex, spaces/colons optional, several packets allowed; "
                        "repeat the option for more")
    parser.add_argument("--direction", choices=sorted(_DIRECTION_ALIASES),
                        help="direction of --hex bytes (default: inferred per packet from the reply bit)")
    parser.add_argument("--tx-id", type=parse_int, default=HOST_TX_ID,
                        help=f"CAN id the host sends on (default 0x{HOST_TX_ID:03X})")
    parser.add_argument("--rx-id", type=parse_int, default=HOST_RX_ID,
                        help=f"CAN id the gimbal answers on (default 0x{HOST_RX_ID:03X})")
    add_legacy_order_option(parser)
    parser.set_defaults(func=run)


def parse_hex(text: str) -> bytes:
    """Bytes from hex text; whitespace, colons, commas and 0x prefixes are ignored."""
    digits = _SEPARATORS.sub("", text)
    if len(digits) % 2:
        raise CliError(f"--hex: odd number of hex digits ({len(digits)})")
    try:
        return bytes.fromhex(digits)
    except ValueError:
        bad = next(c for c in digits if c not in "0123456789abcdefABCDEF")
        raise CliError(f"--hex: {bad!r} is not a hex digit") from None


def run(args: argparse.Namespace, out: TextIO | None = None) -> int:
    out = out or sys.stdout
    decoder = LogDecoder(args.tx_id, args.rx_id, args.legacy_order)
    if args.hex is not None:
        direction = _DIRECTION_ALIASES[args.direction] if args.direction else None
        data = b"".join(parse_hex(text) for text in args.hex)
        _emit(decoder.feed_bytes(data, direction), out)
        _emit(decoder.finish(), out)
        return 0
    if args.direction:
        raise CliError("--direction applies to --hex only; a log's directions come from its CAN ids")
    last = None
    with closing(iter_log_frames(args.log, "decode")) as frames:
        for frame in frames:
            last = frame.timestamp
            _emit(decoder.feed_frame(frame), out)
    _emit(decoder.finish(last), out)
    return 0


def iter_log_frames(path: str, command: str) -> Iterator[can.Message]:
    """The frames of a CAN log; ``CliError`` when it cannot be opened or read. A log without
    frames gets a note on stderr from ``gimbaltrack <command>``."""
    reader = _open_log(path)
    frames = 0
    try:
        iterator = iter(reader)
        while (frame := _next_frame(iterator, path, frames)) is not None:
            frames += 1
            yield frame
    finally:
        _close(reader)
    if frames == 0:
        print(f"gimbaltrack {command}: note: {path} holds no CAN frames", file=sys.stderr)


def _next_frame(iterator: Iterator[can.Message], path: str, frames: int) -> can.Message | None:
    """The log's next frame, None at its end; a reader failure means the file is unreadable."""
    try:
        return next(iterator, None)
    except Exception as exc:  # python-can's readers raise many types (ValueError, BLFParseError, ...)
        where = "at its first frame" if frames == 0 else f"after frame {frames}"
        raise CliError(f"{path}: unreadable {where}: {_reason(exc)}") from exc


def check_log_path(path: str) -> None:
    """``CliError`` unless ``path`` names a file (python-can would judge its suffix first)."""
    if not path.strip():
        raise CliError("an empty path: give a CAN log")
    if not os.path.exists(path):
        raise CliError(f"{path}: no such file")
    if os.path.isdir(path):
        raise CliError(f"{path}: is a directory, not a CAN log")


def _open_log(path: str) -> Iterable[can.Message]:
    check_log_path(path)
    try:
        return can.LogReader(path)
    except Exception as exc:  # unknown suffix (ValueError), bad header (BLFParseError, struct.error), ...
        raise CliError(f"{path}: cannot read as a CAN log: {_reason(exc)}") from exc


def _reason(exc: Exception) -> str:
    """What is wrong with a CAN log, in a user's words rather than Python's (python-can's own are kept)."""
    text = str(exc)
    if match := _BAD_NUMBER.fullmatch(text):
        kind = "hexadecimal number" if match["base"] == "16" else "number"
        return f"{match['value']} is not a {kind}"
    if "values to unpack" in text:
        return "a line has too few or too many fields for this format"
    if isinstance(exc, binascii.Error):
        return "its data is not valid base64"
    if isinstance(exc, UnicodeDecodeError):
        return "it is not a text file"
    if isinstance(exc, (struct.error, zlib.error, EOFError)):
        return "it is cut short or corrupt"
    return text


def _close(reader: Any) -> None:
    stop = getattr(reader, "stop", None)
    if callable(stop):
        stop()


def _emit(records: list[dict[str, Any]], out: TextIO) -> None:
    for record in records:
        out.write(json.dumps(record) + "\n")

