"""``gimbaltrack config``: the settings a run would use, and where each comes from."""
from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from pipelines.cli.bus import SIM_INTERFACE, python_can_config
from pipelines.cli.profile import SCHEMA, Key, Profile, profile_path, read_profile

#: The python-can settings that its own configuration (env, can.rc, ~/.canrc) can give.
PYTHON_CAN_KEYS = ("interface", "channel", "bitrate")


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "config", help="print the effective settings (rig profile, python-can configuration, defaults)",
        description="Print every setting a rig profile can hold, with the value a run of `gimbaltrack track` "
        "would use and where it comes from: the profile (--profile FILE, or ./gimbaltrack.toml), python-can's "
        "own configuration (CAN_* variables, can.rc, ~/.canrc) for the bus, or the built-in default. "
        "Options given on a command line win over all of these.")
    parser.add_argument("--json", action="store_true", help="one JSON object: {key: {value, source}}")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from pipelines.cli import track_cmd  # the command whose options the profile's keys stand for

    parser = argparse.ArgumentParser(prog="gimbaltrack")
    track_cmd.register(parser.add_subparsers())
    defaults = {action.dest: action.default for action in _track_parser(parser)._actions}
    path = profile_path(["--profile", args.profile] if args.profile else [])
    rows = effective_settings(defaults, read_profile(path, parser) if path is not None else None)
    if args.json:
        print(json.dumps({name: {"value": str(value) if isinstance(value, Path) else value, "source": source}
                          for name, value, source in rows}, indent=2))
        return 0
    width = max(len(name) for name, _, _ in rows)
    for name, value, source in rows:
        print(f"{name:<{width}}  {_shown(name, value):<24}  {source}")
    return 0


def effective_settings(defaults: dict[str, Any], profile: Profile | None) -> list[tuple[str, Any, str]]:
    """(``[section].key``, value, source) for every profile key, in the schema's order.
    ``defaults``: ``track``'s own option defaults, by dest, before any profile."""
    can_config = _python_can_config()
    rows = []
    for section, keys in SCHEMA.items():
        for name, key in keys.items():
            label = f"[{section}].{name}"
            if profile is not None and key.dest in profile.values:
                value, source = _as_key(profile.values[key.dest], key), f"profile {profile.path}"
            elif section == "bus" and name in PYTHON_CAN_KEYS and can_config.get(name) is not None:
                value, source = can_config[name], "python-can configuration"
            else:
                value, source = _as_key(defaults.get(key.dest), key), "default"
                if label == "[bus].interface" and value is None:  # track's own fallback (bus.choose_track_bus)
                    value = SIM_INTERFACE
            rows.append((label, value, source))
    return rows


def _track_parser(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    subparsers = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return subparsers.choices["track"]


def _as_key(value: Any, key: Key) -> Any:
    """An option's value as the profile key spells it (``--no-video`` given is ``video = false``)."""
    return (not value) if key.inverted else value


def _python_can_config() -> dict[str, Any]:
    """What python-can's own configuration sets (env, can.rc, ~/.canrc), without opening a bus; a
    broken one is the same one-line error a bus command gives."""
    config = python_can_config({}) or {}
    return {key: config.get(key) for key in PYTHON_CAN_KEYS}


def _shown(name: str, value: Any) -> str:
    """As a TOML file would spell it; CAN ids in hex, as they are written everywhere else."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if name.endswith("_id]") or name.endswith("_id"):
        return f"0x{value:03X}"
    return "-" if value is None else str(value)
