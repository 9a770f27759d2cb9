"""gaitbot robot export --mjcf read by MuJoCo, export-then-import round trips, and a model by other authors.

- MuJoCo's own forward kinematics of the exported MJCF put every link where gaitbot's leg model does at
  random poses (1e-9 m); its total mass is the config's and its centre of mass gaitbot's mass model's.
- Export (URDF and MJCF) then import gives back the config: geometry, every link's mass, centre of mass and
  inertia (1e-9), the joints' limits, and with --like the bus settings by joint.
- MuJoCo Menagerie's OP3 (tools/op3_menagerie.py, meshes removed) imports with --like config/op3.toml, its
  joints found by their names, to a config whose generated walk, played open loop on that same model, does
  not fall and travels within 15% of the plan (issue 24).
"""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

from gaitbot.sim import SimUnavailable, import_mujoco  # noqa: E402  (picks the offscreen GL first)

try:
    mujoco = import_mujoco()
except SimUnavailable:
    pytest.skip("the sim extra (MuJoCo) is not installed", allow_module_level=True)

from helpers import REPO_ROOT, run_cli  # noqa: E402

from gaitbot.gait.body import LEG_LINKS  # noqa: E402
from gaitbot.gait.joints import LEG_JOINT_KINDS, SIDES  # noqa: E402
from gaitbot.gait.kinematics6 import leg_frames  # noqa: E402
from gaitbot.gait.mass import MassModel  # noqa: E402
from gaitbot.gait.trajectory import Trajectory  # noqa: E402
from gaitbot.robot.config import load_robot_config, resolve_config, shipped_config_names  # noqa: E402
from gaitbot.sim.model3d import exported_mjcf  # noqa: E402

POSES = 60
TOLERANCE_M = 1e-9
PLAN_SHARE = 0.15


def _angles(config, rng) -> dict[str, float]:
    angles = {j.name: rng.uniform(math.radians(j.min_deg), math.radians(j.max_deg)) for j in config.walking_joints}
    angles.update({j.name: math.radians(j.hold_deg) for j in config.held_joints})
    return angles


@pytest.mark.parametrize("name", shipped_config_names())
def test_mjcf_forward_kinematics_mass_and_centre_of_mass_are_the_configs(name):
    config = load_robot_config(resolve_config(name))
    model = mujoco.MjModel.from_xml_string(exported_mjcf(config))
    data = mujoco.MjData(model)
    torso = model.body("torso").id
    assert model.body_subtreemass[torso] == pytest.approx(config.body.total_kg, abs=1e-9)
    assert {model.joint(j).name for j in range(1, model.njnt)} == set(config.walking_joint_names)
    mass_model = MassModel.of(config.body)
    rng = np.random.default_rng(24)
    for _ in range(POSES):
        angles = _angles(config, rng)
        for joint in config.walking_joint_names:
            data.qpos[model.joint(joint).qposadr[0]] = angles[joint]
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        root_r, root_p = data.xmat[torso].reshape(3, 3), data.xpos[torso]
        q12 = []
        for side in SIDES:
            q = np.array([angles.get(f"{kind}_{side}", 0.0) for kind in LEG_JOINT_KINDS])
            q12.append(q)
            rotations, origins = leg_frames(config.body.geometry, side, q)
            for k, link in enumerate(LEG_LINKS):
                body = model.body(f"{link}_{side}").id
                assert np.abs(root_r.T @ (data.xpos[body] - root_p) - origins[k]).max() < TOLERANCE_M
                assert np.abs(root_r.T @ data.xmat[body].reshape(3, 3) - rotations[k]).max() < 1e-8
        com = root_r.T @ (data.subtree_com[torso] - root_p)
        assert np.abs(com - mass_model.com_in_root(np.concatenate(q12))).max() < TOLERANCE_M


def _same_body(a, b, tolerance=1e-9):
    ga, gb = a.body.geometry, b.body.geometry
    for key in ga.__dataclass_fields__:
        assert getattr(ga, key) == pytest.approx(getattr(gb, key), abs=tolerance), key
    for name in ("torso",) + LEG_LINKS:
        la = a.body.torso if name == "torso" else a.body.leg_links[name]
        lb = b.body.torso if name == "torso" else b.body.leg_links[name]
        assert la.mass_kg == pytest.approx(lb.mass_kg, abs=tolerance), name
        assert np.abs(la.com_m - lb.com_m).max() < tolerance, name
        assert np.abs(la.inertia_kg_m2 - lb.inertia_kg_m2).max() < tolerance, name


@pytest.mark.parametrize("kind", ["urdf", "mjcf"])
@pytest.mark.parametrize("name", shipped_config_names())
def test_export_then_import_gives_back_the_config(tmp_path, capsys, name, kind):
    description = tmp_path / f"{name}.{'urdf' if kind == 'urdf' else 'xml'}"
    assert run_cli(capsys, "robot", "export", name, f"--{kind}", description)[0] == 0
    out = tmp_path / "back.toml"
    code, stdout, err = run_cli(capsys, "robot", "import", description, "--like", name, "-o", out)
    assert code == 0, err
    original, back = load_robot_config(resolve_config(name)), load_robot_config(out)
    _same_body(original, back)
    assert back.joint_names == original.joint_names and back.draft is None
    for a, b in zip(original.joints, back.joints):
        assert (a.id, a.model, a.direction, a.hold_deg) == (b.id, b.model, b.direction, b.hold_deg)
        assert (a.min_deg, a.max_deg) == pytest.approx((b.min_deg, b.max_deg), abs=1e-9)
    assert (back.gait, back.bus, back.balance) == (original.gait, original.bus, original.balance)
    assert 'knee_pitch_left = "knee_pitch_left"' in stdout


@pytest.fixture(scope="module")
def menagerie(tmp_path_factory):
    sys.path.insert(0, str(REPO_ROOT / "tools"))
    import op3_menagerie

    path = tmp_path_factory.mktemp("menagerie") / "op3.xml"
    path.write_text(op3_menagerie.menagerie_mjcf())
    return op3_menagerie, path


def test_menagerie_op3_imports_by_joint_names(tmp_path, capsys, menagerie):
    """Their joints by their names, each sign from its axis (ROBOTIS's senses: config/op3.toml's directions),
    their geometry and masses gaitbot's op3's (the same robot, described by other authors) to 0.1 mm / 0.1 g,
    the torso apart (the arms at Menagerie's zero pose, not at ROBOTIS's initial pose as op3.toml's)."""
    tools, path = menagerie
    out = tmp_path / "mine.toml"
    code, stdout, err = run_cli(capsys, "robot", "import", path, "--like", resolve_config("op3"), "-o", out)
    assert code == 0, err
    op3, mine = load_robot_config(resolve_config("op3")), load_robot_config(out)
    for joint in op3.joints:
        theirs, sign = tools.their_joint(joint.name)
        assert f'{joint.name} = "{"-" if sign < 0 else ""}{theirs}"' in stdout
        assert mine.joint(joint.name).direction == joint.direction == sign
    for key in ("thigh_m", "shank_m", "foot_m", "foot_width_m", "hip_width_m", "ankle_height_m", "heel_back_m",
                "sole_outward_m", "hip_below_root_m"):
        assert getattr(mine.geometry, key) == pytest.approx(getattr(op3.geometry, key), abs=1.1e-4), key
    for name in LEG_LINKS:
        assert mine.body.leg_links[name].mass_kg == pytest.approx(op3.body.leg_links[name].mass_kg, abs=1e-4)
    assert mine.body.total_kg == pytest.approx(op3.body.total_kg, abs=1e-4)


def test_the_imported_menagerie_op3_walks_on_that_model(tmp_path, capsys, menagerie):
    tools, path = menagerie
    out, walk = tmp_path / "mine.toml", tmp_path / "walk.npz"
    assert run_cli(capsys, "robot", "import", path, "--like", resolve_config("op3"), "-o", out)[0] == 0
    assert run_cli(capsys, "generate", "--robot", out, "--distance", "1", "-o", walk)[0] == 0
    result = tools.play(Trajectory.load(walk), 60.0)
    assert not result.fell, result
    assert abs(result.distance_travelled_m / result.distance_planned_m - 1) <= PLAN_SHARE, result
