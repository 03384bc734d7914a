"""Rig profiles: a TOML file that holds one rig's settings, so a real gimbal needs no long command line.

A profile fills in the defaults of the options it names, for whichever subcommand has them; what the
command line gives still wins. Keys are grouped the way a rig is described (the bus with python-can's
own names, the gimbal's conventions, the camera, control, tracker, outputs). Each value goes through
the same conversion and checks as the option it stands for, so a profile cannot hold what the command
line would refuse; an unknown key or a bad value is one line naming the key and the file.
"""
from __future__ import annotations

import argparse
import tomllib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pipelines.cli.common import CliError

#: The profile read from the working folder when no ``--profile`` is given.
LOCAL_PROFILE = "gimbaltrack.toml"
PROFILE_OPTION = "--profile"
#: Subcommands that play the gimbal, not the host: a rig's bus and ids are not theirs.
DEVICE_COMMANDS = ("sim",)


@dataclass(frozen=True)
class Key:
    """One profile key: the option it stands for, and for a switch whether ``true`` means the
    option is off (``video = false`` is ``--no-video``)."""

    option: str
    inverted: bool = False

    @property
    def dest(self) -> str:
        return self.option.lstrip("-").replace("-", "_")


SCHEMA: dict[str, dict[str, Key]] = {
    "bus": {"interface": Key("--interface"), "channel": Key("--channel"), "bitrate": Key("--bitrate"),
            "tx_id": Key("--tx-id"), "rx_id": Key("--rx-id")},
    "gimbal": {"invert_yaw": Key("--invert-yaw"), "invert_pitch": Key("--invert-pitch"),
               "invert_yaw_attitude": Key("--invert-yaw-attitude"),
               "invert_pitch_attitude": Key("--invert-pitch-attitude"),
               "attitude_feedback": Key("--attitude-feedback"), "legacy_order": Key("--legacy-order")},
    "camera": {"hfov": Key("--hfov")},
    "control": {"controller": Key("--controller"), "rate": Key("--rate"), "max_speed": Key("--max-speed")},
    "tracker": {"tracker": Key("--tracker"), "model_dir": Key("--model-dir"), "detect": Key("--detect"),
                "pick": Key("--pick")},
    "outputs": {"out": Key("--out"), "video": Key("--no-video", inverted=True), "video_width": Key("--video-width"),
                "record": Key("--record")},
}


@dataclass
class Profile:
    """The settings read from one file: ``values`` by argparse dest, and which key each came from."""

    path: Path
    values: dict[str, Any] = field(default_factory=dict)
    keys: dict[str, str] = field(default_factory=dict)  # dest -> "[section].key"

    def where(self, dest: str) -> str:
        return f"{self.keys[dest]} in {self.path}"


def profile_path(argv: Sequence[str], cwd: Path | None = None) -> Path | None:
    """The profile a run uses: ``--profile FILE`` wherever it stands, else ./gimbaltrack.toml if
    there is one. ``--profile`` without a value is left for argparse to refuse."""
    for i, arg in enumerate(argv):
        if arg == "--":
            break
        if arg == PROFILE_OPTION and i + 1 < len(argv):
            return Path(argv[i + 1])
        if arg.startswith(PROFILE_OPTION + "="):
            return Path(arg.split("=", 1)[1])
    local = (cwd or Path.cwd()) / LOCAL_PROFILE
    return local if local.is_file() else None


def add_profile_option(parser: argparse.ArgumentParser, default: object = None) -> None:
    parser.add_argument(PROFILE_OPTION, metavar="FILE", default=default,
                        help=f"rig profile (TOML) whose settings stand in for options not given "
                        f"(default: ./{LOCAL_PROFILE} when present; see docs/hardware.md)")


def read_profile(path: Path, parser: argparse.ArgumentParser) -> Profile:
    """The profile at ``path``, each value converted and checked as ``parser``'s option for it is."""
    if path.is_dir():
        raise CliError(f"profile {path}: is a folder, not a file")
    try:
        document = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise CliError(f"profile {path}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise CliError(f"profile {path}: cannot read it: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise CliError(f"profile {path}: not valid TOML: {exc}") from None
    actions = {action.dest: action for action in _all_actions(parser)}
    profile = Profile(path)
    for section, table in document.items():
        if section not in SCHEMA:
            raise CliError(f"profile {path}: unknown section [{section}] (known: {', '.join(SCHEMA)})")
        if not isinstance(table, dict):
            raise CliError(f"profile {path}: {section} must be a table ([{section}])")
        for name, value in table.items():
            key = SCHEMA[section].get(name)
            label = f"[{section}].{name}"
            if key is None:
                raise CliError(f"profile {path}: unknown key {label} (known in [{section}]: "
                               f"{', '.join(SCHEMA[section])})")
            try:
                profile.values[key.dest] = _converted(value, key, actions[key.dest])
            except (argparse.ArgumentTypeError, ValueError, TypeError) as exc:
                raise CliError(f"profile {path}: {label}: {exc}") from None
            profile.keys[key.dest] = label
    return profile


def _converted(value: Any, key: Key, action: argparse.Action) -> Any:
    """``value`` as the option's own conversion and choices would take it from the command line."""
    if action.nargs == 0:  # a switch: store_true
        if not isinstance(value, bool):
            raise TypeError(f"must be true or false, not {value!r}")
        return value != key.inverted
    numeric = action.type in (int, float)
    if isinstance(value, (bool, dict, list)) or (numeric and isinstance(value, str)):
        raise TypeError(f"must be a {'number' if numeric else 'string or number'}, not {value!r}")
    converted = action.type(str(value)) if action.type is not None else str(value)
    if action.choices is not None and converted not in action.choices:
        raise ValueError(f"{converted!r} is not one of {', '.join(map(str, action.choices))}")
    return converted


def apply_profile(parser: argparse.ArgumentParser, profile: Profile) -> None:
    """Make the profile's values the defaults of every (sub)parser option they stand for; an option
    whose default is suppressed (a repeated copy that defers to its parent's) is left alone."""
    for action in _all_actions(parser):
        if action.dest in profile.values and action.default is not argparse.SUPPRESS:
            action.default = profile.values[action.dest]


def given_on_command_line(argv: Sequence[str], parser: argparse.ArgumentParser) -> set[str]:
    """The dests whose options ``argv`` names (``-i can``, ``--max-speed=30``): those the profile
    did not decide."""
    strings = {s: action.dest for action in _all_actions(parser) for s in action.option_strings}
    given = set()
    for arg in argv:
        if arg == "--":
            break
        name = arg.split("=", 1)[0] if arg.startswith("--") else arg[:2] if arg.startswith("-") else None
        if name in strings:
            given.add(strings[name])
    return given


def blame(message: str, profile: Profile, argv: Sequence[str], parser: argparse.ArgumentParser) -> str:
    """``message`` with the profile key named when it is about an option the profile set (a command's
    own range checks speak of ``--max-speed``; the user wrote ``[control].max_speed``)."""
    given = given_on_command_line(argv, parser)
    for section in SCHEMA.values():
        for key in section.values():
            if key.dest in profile.values and key.dest not in given and key.option in message:
                return f"{message} (from {profile.where(key.dest)})"
    return message


def _all_actions(parser: argparse.ArgumentParser) -> Iterator[argparse.Action]:
    """Every option of ``parser`` and of its subcommands at any depth, but the device side's."""
    pending = [parser]
    while pending:
        current = pending.pop()
        for action in current._actions:
            if isinstance(action, argparse._SubParsersAction):
                pending += [sub for name, sub in action.choices.items() if name not in DEVICE_COMMANDS]
            else:
                yield action
