"""gaitbot robot export / import on the command line: bad descriptions refused in one line (exit 2, no
traceback, nothing written), a --map file when the names do not say, and a draft that plans and simulates but
is refused for hardware. Each refusal runs in a forked child with bounded time and memory (helpers.cli)."""

from __future__ import annotations

import re

import pytest
from helpers import assert_cli_behaves, cli, run_cli

from gaitbot.robot.config import load_robot_config, resolve_config
from gaitbot.robot.description.urdf_writer import urdf_text
from gaitbot.robot.description.tree import MAX_DESCRIPTION_BYTES


@pytest.fixture(scope="module")
def op3_urdf() -> str:
    return urdf_text(load_robot_config(resolve_config("op3")))


def joint_element(text: str, name: str) -> str:
    return re.search(rf'<joint name="{name}".*?</joint>', text).group(0)


def refused(tmp_path, name: str, content: str | bytes, *extra: str) -> str:
    """Import ``content`` (written to ``name``): exit 2, one line naming the file; that line."""
    path = tmp_path / name
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    out = tmp_path / "out.toml"
    result = cli("robot", "import", str(path), "-o", str(out), *extra)
    assert_cli_behaves(result, allowed=(2,))
    assert name in result["stderr"] and not out.exists(), result["stderr"]
    return result["stderr"]


def test_a_missing_joint_is_refused(tmp_path, op3_urdf):
    err = refused(tmp_path, "missing.urdf", op3_urdf.replace(joint_element(op3_urdf, "knee_pitch_left"), ""))
    assert "shank_left" in err and "missing joint" in err


def test_a_cycle_is_refused(tmp_path, op3_urdf):
    knee = joint_element(op3_urdf, "hip_pitch_left")
    err = refused(tmp_path, "cycle.urdf", op3_urdf.replace(knee, knee.replace('parent link="hip_roll_left"',
                                                                                 'parent link="foot_left"')))
    assert "cycle" in err


def test_a_leg_with_five_joints_is_refused_naming_them(tmp_path, op3_urdf):
    roll = joint_element(op3_urdf, "ankle_roll_left")
    err = refused(tmp_path, "five.urdf", op3_urdf.replace(roll, roll.replace('type="revolute"', 'type="fixed"')))
    assert "left leg: 5 joints found (hip_yaw, hip_roll, hip_pitch, knee_pitch, ankle_pitch)" in err


@pytest.mark.parametrize("mass", ["0", "-0.1", "nan", "1e400"])
def test_zero_negative_or_unreadable_masses_are_refused(tmp_path, op3_urdf, mass):
    text = re.sub(r'(<link name="thigh_left">.*?<mass value=")[^"]*', rf"\g<1>{mass}", op3_urdf, count=1)
    err = refused(tmp_path, "mass.urdf", text)
    assert "thigh_left" in err


@pytest.mark.parametrize("name, content, words", [
    ("notxml.urdf", "this is not a robot <", "not XML"),
    ("html.xml", "<html><body/></html>", "neither a URDF"),
    ("bad.xml", "<mujoco><worldbody><body><joint type='hinge' axis='0 0 0'/></body></worldbody></mujoco>",
     "MuJoCo cannot compile"),
    ("bomb.urdf", '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;">]>'
                  "<robot>&b;</robot>", "entities"),
    ("empty.urdf", "<robot name='x'/>", "no <link>"),
])
def test_unusable_files_are_refused(tmp_path, name, content, words):
    assert words in refused(tmp_path, name, content)


def test_an_unknown_file_and_a_huge_one_are_refused(tmp_path):
    result = cli("robot", "import", str(tmp_path / "nowhere.urdf"), "-o", str(tmp_path / "out.toml"))
    assert_cli_behaves(result, allowed=(2,))
    assert "nowhere.urdf" in result["stderr"]
    huge = tmp_path / "huge.urdf"
    with open(huge, "wb") as f:
        f.truncate(MAX_DESCRIPTION_BYTES + 1)
    assert "larger than" in refused(tmp_path, "huge.urdf", huge.read_bytes())


def test_names_that_do_not_say_need_a_map_file_whose_signs_the_axes_check(tmp_path, capsys, op3_urdf):
    """Joints renamed j1..j12: refused naming --map; with a map file in the sim room's form it imports, and a
    map whose sign contradicts the axes is refused naming the joint and the right form."""
    text, names = op3_urdf, {}
    for i, joint in enumerate(re.findall(r'<joint name="(\w+)" type="revolute"', op3_urdf), start=1):
        names[joint] = f"j{i}"
        text = text.replace(f'<joint name="{joint}"', f'<joint name="j{i}"')
    assert "--map" in refused(tmp_path, "anon.urdf", text)
    mapping = tmp_path / "map.toml"
    mapping.write_text("[joints]\n" + "".join(f'{ours} = "{theirs}"\n' for ours, theirs in names.items()))
    out = tmp_path / "mapped.toml"
    code, stdout, err = run_cli(capsys, "robot", "import", tmp_path / "anon.urdf", "--map", mapping, "--like", "op3",
                                "-o", out)
    assert code == 0, err
    assert 'knee_pitch_left = "j4"' in stdout
    assert load_robot_config(out).body.total_kg == pytest.approx(load_robot_config(resolve_config("op3")).body.total_kg)
    mapping.write_text(mapping.read_text().replace('= "j4"', '= "-j4"'))
    err = refused(tmp_path, "anon.urdf", text, "--map", str(mapping))
    assert 'knee_pitch_left = \\"j4\\"' in err or 'knee_pitch_left = "j4"' in err


def test_a_draft_plans_and_simulates_but_hardware_refuses_it(tmp_path, capsys):
    description, draft = tmp_path / "op3.urdf", tmp_path / "draft.toml"
    assert run_cli(capsys, "robot", "export", "op3", "--urdf", description)[0] == 0
    code, stdout, err = run_cli(capsys, "robot", "import", description, "-o", draft)
    assert code == 0 and "a draft" in stdout, err
    assert load_robot_config(draft).draft is not None
    assert run_cli(capsys, "plan", "--robot", draft, "--distance", "0.2")[0] == 0
    assert run_cli(capsys, "walk", "--robot", draft, "--distance", "0.2", "--dry-run")[0] == 0
    code, _, err = run_cli(capsys, "walk", "--robot", draft, "--distance", "0.2", "--port", "/dev/ttyUSB0")
    assert code == 2 and "robot.draft" in err


def test_export_needs_an_output(tmp_path, capsys):
    code, _, err = run_cli(capsys, "robot", "export", "op3")
    assert code == 2 and "--urdf" in err


@pytest.fixture(scope="module")
def menagerie_mjcf() -> str:
    import sys

    from helpers import REPO_ROOT

    from gaitbot.sim import SimUnavailable, import_mujoco

    try:
        import_mujoco()
    except SimUnavailable:
        pytest.skip("the sim extra (MuJoCo) is not installed")
    sys.path.insert(0, str(REPO_ROOT / "tools"))
    import op3_menagerie

    return op3_menagerie.menagerie_mjcf()


@pytest.mark.parametrize("mass, words", [("0", "inertial mass 0 kg: must be positive"),
                                         ("-0.04", "inertial mass -0.04 kg: must be positive")])
def test_an_mjcf_by_other_authors_with_a_bad_mass_is_refused(tmp_path, menagerie_mjcf, mass, words):
    text = re.sub(r'(<body name="l_knee_link"[^>]*><inertial[^>]*mass=")[^"]*', rf"\g<1>{mass}", menagerie_mjcf)
    err = refused(tmp_path, "op3.xml", text, "--like", "op3")
    assert "body l_knee_link" in err and words in err


def test_an_mjcf_leg_without_its_knee_is_refused(tmp_path, menagerie_mjcf):
    text = re.sub(r'<joint name="l_knee"[^>]*/>', "", menagerie_mjcf).replace('<position name="l_knee_act" '
                                                                             'joint="l_knee"/>', "")
    err = refused(tmp_path, "op3.xml", text, "--like", "op3")
    assert "left leg: 5 joints found (hip_yaw, hip_roll, hip_pitch, ankle_pitch, ankle_roll)" in err


def test_feet_without_boxes_take_the_like_configs_sole_or_are_refused(tmp_path, capsys, op3_urdf):
    """A description whose feet are meshes only (a CAD export): with --like the sole is that config's (and a
    note says so); without, the import is refused naming the foot."""
    text = re.sub(r"<collision>.*?</collision>", "", op3_urdf)
    assert "<collision>" not in text
    assert "no box collision shape on the left foot" in refused(tmp_path, "meshes.urdf", text)
    out = tmp_path / "sole.toml"
    code, _, err = run_cli(capsys, "robot", "import", tmp_path / "meshes.urdf", "--like", "op3", "-o", out)
    assert code == 0 and "the sole is the --like config's" in err
    assert load_robot_config(out).geometry == load_robot_config(resolve_config("op3")).geometry
