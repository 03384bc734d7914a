"""The CAN logs ``decode`` and ``replay`` read: python-can's readers, a log cut short read up to its
last whole line, and standard input (``-``) for ``candump -L can0 | gimbaltrack decode -``."""
from __future__ import annotations

import binascii
import io
import os
import re
import struct
import sys
import zlib
from collections.abc import Callable, Iterable, Iterator
from typing import Any, TextIO

import can

from pipelines.cli.common import CliError

STDIN = "-"
STDIN_NAME = "standard input"
#: python-can's text readers, which can read a stream (``-``); .blf, .db and .mf4 need a file.
STDIN_FORMATS: dict[str, Callable[[TextIO], Iterable[can.Message]]] = {
    "log": can.CanutilsLogReader, "asc": can.ASCReader, "csv": can.CSVReader, "trc": can.TRCReader}

# How Python words a field that does not parse as a number, as python-can's readers pass it on.
_BAD_NUMBER = re.compile(r"(?:invalid literal for int\(\) with base (?P<base>\d+)|"
                         r"could not convert string to float): (?P<value>.*)")
# What ``candump can0`` prints without -L: "  can0  223   [8]  AA 13 00 ...".
_CANDUMP_SCREEN = re.compile(r"\s*\S+\s+[0-9A-Fa-f]{3,8}\s+\[\d+\]")


class WholeLines:
    """A text log's lines for a python-can reader, up to the last whole one. A last line without
    its line end was cut mid-write, and may still parse, as a wrong frame ('223#AA1' reads as
    the bytes AA 01): it is held back, and ``cut_short`` says why."""

    def __init__(self, file: TextIO) -> None:
        self._file = file
        self.lines = 0  # whole lines handed out
        self.last = ""  # the last of them, which a reader failure is about
        self.cut_short: str | None = None

    def __iter__(self) -> WholeLines:
        return self

    def __next__(self) -> str:
        if self.cut_short is not None:
            raise StopIteration
        try:
            line = self._file.readline()
        except EOFError:  # gzip: the compressed stream stops before its end marker
            self.cut_short = f"the compressed file ends early, after line {self.lines}"
            raise StopIteration from None
        if not line:
            raise StopIteration
        if not line.endswith("\n"):
            self.cut_short = f"line {self.lines + 1} is cut short (no line end)"
            raise StopIteration
        self.lines += 1
        self.last = line
        return line

    def close(self) -> None:
        self._file.close()


class LogFrames:
    """The frames of a CAN log for ``gimbaltrack <command>``: a log that cannot be opened is a
    ``CliError`` at once; one cut short at the end is a warning on stderr; a frame unreadable part
    way ends the frames, and ``check()`` raises its ``CliError`` once what was read is out."""

    def __init__(self, path: str, command: str, fmt: str | None = None) -> None:
        self.name = STDIN_NAME if path == STDIN else path
        self.command = command
        self.reader, self.lines = open_log(path, fmt)
        self.frames = 0
        self.error: CliError | None = None

    def __iter__(self) -> Iterator[can.Message]:
        iterator = iter(self.reader)
        while True:
            try:
                frame = next(iterator, None)
            except Exception as exc:  # python-can's readers raise many types (ValueError, BLFParseError, ...)
                where = "at its first frame" if self.frames == 0 else f"after frame {self.frames}"
                self.error = CliError(f"{self.name}: unreadable {where}: {self._reason(exc)}")
                return
            if frame is None:
                break
            self.frames += 1
            yield frame
        if self.lines is not None and self.lines.cut_short:
            if self.lines.lines == 0:  # not one whole line: nothing that was ever a log
                self.error = CliError(f"{self.name}: unreadable at its first frame: {self.lines.cut_short}")
                return
            self._say("warning", f"{self.name}: {self.lines.cut_short}: left out, the frames before it are kept")
        if self.frames == 0:
            self._say("note", f"{self.name} holds no CAN frames")

    def check(self) -> None:
        """Raise the failure that ended the frames early, if any."""
        if self.error is not None:
            raise self.error

    def close(self) -> None:
        close_reader(self.reader)

    def _say(self, kind: str, text: str) -> None:
        print(f"gimbaltrack {self.command}: {kind}: {text}", file=sys.stderr)

    def _reason(self, exc: Exception) -> str:
        if self.lines is not None and isinstance(self.reader, can.CanutilsLogReader) \
                and _CANDUMP_SCREEN.match(self.lines.last):
            return "this is candump's screen layout; run candump with -L for its log format"
        return reason(exc)


def check_log_path(path: str) -> None:
    """``CliError`` unless ``path`` names a file (python-can would judge its suffix first)."""
    if not path.strip():
        raise CliError("an empty path: give a CAN log")
    if not os.path.exists(path):
        raise CliError(f"{path}: no such file")
    if os.path.isdir(path):
        raise CliError(f"{path}: is a directory, not a CAN log")


def open_log(path: str, fmt: str | None = None) -> tuple[Iterable[can.Message], WholeLines | None]:
    """(python-can's reader for ``path``, or for standard input in ``fmt``; the whole lines it
    reads when the log is text). ``CliError`` when it cannot be opened."""
    if fmt is not None and path != STDIN:
        raise CliError("--format applies to - (standard input) only; a file's format comes from its suffix")
    if path == STDIN:
        if sys.stdin is None:  # fd 0 closed
            raise CliError("standard input is closed: give a CAN log file")
        lines = WholeLines(sys.stdin)
        return STDIN_FORMATS[fmt or "log"](lines), lines
    check_log_path(path)
    try:
        reader = can.LogReader(path)
    except Exception as exc:  # unknown suffix (ValueError), bad header (BLFParseError, struct.error), ...
        raise CliError(f"{path}: cannot read as a CAN log: {reason(exc)}") from exc
    file = getattr(reader, "file", None)
    if not isinstance(file, io.TextIOBase):
        return reader, None
    reader.file = lines = WholeLines(file)  # type: ignore[attr-defined]  # text readers iterate it as they go
    return reader, lines


def reason(exc: Exception) -> str:
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


def close_reader(reader: Any) -> None:
    stop = getattr(reader, "stop", None)
    if callable(stop):
        stop()
