"""config/op3.toml's mass table is what tools/op3_mass_table.py derives from ROBOTIS's link table, and it
adds up (the config reader checks [mass] total_kg against the links)."""

from __future__ import annotations

import subprocess
import sys

from gaitbot.robot.config import load_robot_config
from helpers import CONFIG_DIR, REPO_ROOT


def test_op3_links_are_the_derivation_of_robotis_table():
    done = subprocess.run([sys.executable, str(REPO_ROOT / "tools" / "op3_mass_table.py"), "--check",
                           str(CONFIG_DIR / "op3.toml")], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout
    assert "matches the derivation" in done.stdout


def test_op3_total_mass_is_robotis_table_summed():
    config = load_robot_config(CONFIG_DIR / "op3.toml")
    assert abs(config.body.total_kg - 3.14747) < 1e-4
