"""Servo stiffness as register values: ``[servo] full_torque_error_deg`` -> what is written to each servo.

A position-controlled hobby servo is a proportional loop: its output grows with the position error
and is full (stall torque) at some error; the smaller that error, the stiffer the joint. The robot
config asks for that error in degrees, the same figure for every servo; each model's GainRegister
(gaitbot.servos.models, with its datasheet source) says which register sets it and how a register
value maps to degrees. :func:`gain_for_error` is the one conversion from degrees to a register value,
:func:`full_torque_error_deg` its inverse (what a value in the register gives: the simulated servo
reads its stiffness from its control table with it).

Rounding: a P gain (Dynamixel X, Feetech) is rounded to the nearest integer; the AX-12A's compliance
slope has 7 steps and the step chosen is the largest whose error is not above the one asked (the
stiffer side). Either way the error obtained is reported with the setting. A request the register
cannot hold (a gain past its largest value, an error below the AX's stiffest step) is refused with the
range that model allows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from gaitbot.servos.models import COMPLIANCE_SLOPE, SLOPE_STEPS, GainRegister, ServoModel
from gaitbot.servos.registers import RegisterWrite


class RegisterValue(NamedTuple):
    """One register write: ``value`` as ``length`` bytes at ``address``; ``name`` is the register's."""

    address: int
    length: int
    value: int
    name: str


class GainError(ValueError):
    """A stiffness this servo cannot be given; the message says why and what is allowed (one line)."""


@dataclass(frozen=True)
class GainSetting:
    """The register value that gives ``model`` the stiffness asked for.

    value: what goes into each of the model's gain registers; full_torque_error_deg: the error at which
    the loop then gives full output (the one obtained, after rounding); writes: every register write to
    send to one servo, in order (a Feetech servo's EEPROM lock first)."""

    model: ServoModel
    requested_error_deg: float
    value: int
    full_torque_error_deg: float
    writes: tuple[RegisterValue, ...]

    def describe(self) -> str:
        """One line for people: register, value and the error it gives."""
        gain = self.model.gain
        assumed = " (scale assumed: not documented by the maker)" if gain.assumed else ""
        return (f"{self.model.name} {gain.name} {self.value}: full torque at {self.full_torque_error_deg:.3g} deg "
                f"(asked {self.requested_error_deg:g}){assumed}")


def gain_for_error(model: ServoModel, error_deg: float) -> GainSetting:
    """The register value for full output at ``error_deg`` degrees of position error; GainError if the
    model has no known gain register or the register cannot hold the value."""
    gain = model.gain
    if gain is None:
        raise GainError(f"gaitbot cannot set the stiffness of the {model.name}: no gain register with a "
                        f"documented scale is known for it")
    if not (math.isfinite(error_deg) and error_deg > 0):
        raise GainError(f"must be a positive number of degrees, got {error_deg}")
    if gain.law == COMPLIANCE_SLOPE:
        fitting = [s for s in SLOPE_STEPS if s * gain.deg_per_unit <= error_deg * (1 + 1e-12)]
        if not fitting:
            raise GainError(f"{error_deg:g} deg is stiffer than the {model.name} allows ({_allowed(gain)})")
        value = fitting[-1]
    else:
        value = round(gain.error_deg_times_value / error_deg)
        if not gain.min_value <= value <= gain.max_value:
            raise GainError(f"{error_deg:g} deg needs {gain.name} {value}, outside the {model.name}'s "
                            f"{gain.min_value}..{gain.max_value} ({_allowed(gain)})")
    writes = tuple(RegisterValue(*before) for before in gain.before) + \
        tuple(RegisterValue(address, gain.length, int(value), gain.name) for address in gain.addresses)
    return GainSetting(model, float(error_deg), int(value), gain.full_torque_error_deg(value), writes)


def _allowed(gain: GainRegister) -> str:
    if gain.law == COMPLIANCE_SLOPE:
        low = SLOPE_STEPS[0] * gain.deg_per_unit
        return (f"allowed: {low:.3f} deg or more; the {gain.name} steps {SLOPE_STEPS[0]}..{SLOPE_STEPS[-1]} "
                f"give {low:.3f}..{SLOPE_STEPS[-1] * gain.deg_per_unit:.1f} deg")
    low = gain.error_deg_times_value / gain.max_value
    high = gain.error_deg_times_value / gain.min_value
    return f"allowed: {low:.3f} to {high:.4g} deg"


def gain_plan(config) -> tuple[tuple[GainSetting, tuple[int, ...]], ...]:
    """Per servo model of ``config`` (a RobotConfig): its setting and the ids of its servos, every servo
    of the robot (held joints too). Empty without ``[servo] full_torque_error_deg``: factory gains stay."""
    error_deg = config.servo.full_torque_error_deg
    if error_deg is None:
        return ()
    ids: dict[str, list[int]] = {}
    models: dict[str, ServoModel] = {}
    for joint in config.joints:
        ids.setdefault(joint.model.name, []).append(joint.id)
        models[joint.model.name] = joint.model
    return tuple((gain_for_error(models[name], error_deg), tuple(ids[name])) for name in ids)


def gain_writes(config) -> tuple[RegisterWrite, ...]:
    """What a session writes before torque on to give every servo ``[servo] full_torque_error_deg``
    (nothing without it), one register write per servo model and register (checked at load)."""
    return tuple(RegisterWrite(ids, w.address, w.length, w.value, w.name)
                 for setting, ids in gain_plan(config) for w in setting.writes)


def gain_notes(config) -> list[str]:
    """One line per servo model for people: which gain is written and the stiffness it gives."""
    return [f"servo stiffness: {setting.describe()}, written to ids {', '.join(map(str, sorted(ids)))} before "
            f"torque on (in RAM: lasts until power-off)" for setting, ids in gain_plan(config)]
