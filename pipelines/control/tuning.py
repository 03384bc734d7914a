"""Live settings an operator may change while a run goes on, by their short names, and the
``ControlConfig`` they make (the console's ``/api/settings``; the summary's ``settings``)."""
from __future__ import annotations

import dataclasses
from collections.abc import Mapping

from pipelines.control.controller import ControlConfig

#: Short names -> ``ControlConfig`` fields: deg/s, degrees, and the PID's gains.
SETTING_FIELDS = {"max_speed": "max_speed_dps", "dead_zone": "deadband_deg", "kp": "kp", "ki": "ki", "kd": "kd"}


def retuned(config: ControlConfig, changes: Mapping[str, float]) -> ControlConfig:
    """``config`` with ``changes`` (short names); the acceleration limit is raised only as far as
    the zero-speed ramp of a new speed limit needs (as ``--max-speed`` does). ValueError from
    ``ControlConfig`` for a combination it refuses."""
    fields = {SETTING_FIELDS[name]: value for name, value in changes.items()}
    if "max_speed_dps" in fields:
        fields["max_accel_dps2"] = max(config.max_accel_dps2, fields["max_speed_dps"] / config.ramp_s)
    return dataclasses.replace(config, **fields)


def settings_of(config: ControlConfig) -> dict[str, float]:
    """The live settings as they stand in ``config``, by their short names."""
    return {name: getattr(config, field) for name, field in SETTING_FIELDS.items()}
