"""A servo of another model than the config's is never driven (issue 26 item 3).

The op3 config describes XM430-W350 servos; here the emulator's servos (all twelve, or one) report the
XL430-W250's model number. The walk must stop at its start with exit 1, naming the servo, the model found
and the model expected, before torque on and before anything at all is written to a servo.
"""

from __future__ import annotations

import pytest

from gaitbot.servos.models import servo_model
from helpers import CONFIG_DIR, config, emulator_for, run_cli

XL430 = servo_model("XL430-W250")


@pytest.mark.parametrize("which", ["all", "one"])
def test_a_walk_on_servos_of_another_model_exits_1_before_anything_is_written(capsys, tmp_path, which):
    cfg = CONFIG_DIR / "op3.toml"
    ids = [j.id for j in config("op3").joints] if which == "all" else [14]
    emulator = emulator_for(cfg, tmp_path / "goals.jsonl", model_numbers={i: XL430.model_number for i in ids})
    with emulator as chain:
        code, out, err = run_cli(capsys, "walk", "--robot", str(cfg), "--port", chain.path, "--steps", "0.03")
    assert code == 1, out + err
    text = out + err
    first = ids[0]
    assert (f"servo {first} is a XL430-W250 (model number {XL430.model_number}), the config expects a "
            f"XM430-W350 (model number {servo_model('XM430-W350').model_number})") in text
    assert emulator.chain.writes == []  # no WRITE reached any servo: no gains, no torque on
    assert emulator.chain.goal_frames == 0  # and no goal
