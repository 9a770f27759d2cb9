"""Servo health thresholds of a robot: each servo model's defaults (gaitbot.servos.health), overridden by the
config's optional ``[health]`` table, never past what the servo itself tolerates.

    [health]
    warn_temperature_c = 60.0   # a warning on the status line at or above this
    stop_temperature_c = 65.0   # a safe stop at or above this; at most the servo's shutdown temperature
    warn_voltage_v = 7.0        # a warning at or below this input voltage
    stop_voltage_v = 6.5        # a safe stop at or below this; at least the servo's Min Voltage Limit
    warn_load_pct = 80.0        # a warning at or above this load (% of the maximum torque)

A value given applies to every servo and is checked against each joint's model: a stop temperature above
a servo's own shutdown temperature, or a stop voltage under its own minimum, is refused with the allowed
range (exit 2), as is a warning that would come after the stop. docs/bring-up.md explains the defaults.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable
from typing import Any

from gaitbot.servos.health import HealthThresholds, default_thresholds, servo_limits

HEALTH_KEYS = ("warn_temperature_c", "stop_temperature_c", "warn_voltage_v", "stop_voltage_v", "warn_load_pct")


@dataclasses.dataclass(frozen=True)
class HealthSettings:
    """The ``[health]`` overrides (None: each servo model's default)."""

    warn_temperature_c: float | None = None
    stop_temperature_c: float | None = None
    warn_voltage_v: float | None = None
    stop_voltage_v: float | None = None
    warn_load_pct: float | None = None

    def thresholds(self, model_name: str) -> HealthThresholds:
        """A model's defaults with these overrides."""
        given = {k: v for k, v in dataclasses.asdict(self).items() if v is not None}
        return dataclasses.replace(default_thresholds(model_name), **given)


def read_health(fields: Any, data: dict, joints: Iterable[Any]) -> HealthSettings:
    """The ``[health]`` table of a config (``fields``: its gaitbot.fields.Fields reader), checked against
    every joint's servo model; HealthSettings() when the table is absent."""
    t = fields.optional_table(data, "health", "health", HEALTH_KEYS)
    settings = HealthSettings(**{k: fields.number(t, k, "health", positive=True) if k in t else None
                                 for k in HEALTH_KEYS})
    if settings.warn_load_pct is not None and settings.warn_load_pct > 100:
        raise fields.fail("health.warn_load_pct", f"{settings.warn_load_pct:g} is above 100 % (allowed: 0..100)")
    for joint in joints:
        problem = health_problem(settings, joint.model.name)
        if problem:
            key, reason = problem
            raise fields.fail(f"health.{key}", f"{reason} (joints.{joint.name})")
    return settings


def health_problem(settings: HealthSettings, model_name: str) -> tuple[str, str] | None:
    """(key, reason) when the settings cannot hold for a servo of ``model_name``, else None."""
    limits = servo_limits(model_name)
    t = settings.thresholds(model_name)
    if t.stop_temperature_c > limits.shutdown_temperature_c:
        return "stop_temperature_c", (f"{t.stop_temperature_c:g} C is above the {model_name}'s own shutdown "
                                      f"temperature {limits.shutdown_temperature_c:g} C (allowed: up to "
                                      f"{limits.shutdown_temperature_c:g})")
    if t.warn_temperature_c > t.stop_temperature_c:
        return "warn_temperature_c", (f"{t.warn_temperature_c:g} C is above the stop temperature "
                                      f"{t.stop_temperature_c:g} C (a warning must come first)")
    if t.stop_voltage_v < limits.min_voltage_register_v:
        return "stop_voltage_v", (f"{t.stop_voltage_v:g} V is under the {model_name}'s own minimum input voltage "
                                  f"{limits.min_voltage_register_v:g} V (allowed: {limits.min_voltage_register_v:g} "
                                  "or more)")
    if t.warn_voltage_v < t.stop_voltage_v:
        return "warn_voltage_v", (f"{t.warn_voltage_v:g} V is under the stop voltage {t.stop_voltage_v:g} V "
                                  "(a warning must come first)")
    return None


def health_thresholds(config: Any) -> dict[int, HealthThresholds]:
    """Per servo id of a robot config, the thresholds its session watches."""
    settings = getattr(config, "health", None) or HealthSettings()
    return {j.id: settings.thresholds(j.model.name) for j in config.joints}
