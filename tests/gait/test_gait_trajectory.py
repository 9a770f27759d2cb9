"""Trajectory files: the CSV/NPZ contract every later room reads, and clear errors on bad files."""

from __future__ import annotations

import numpy as np
import pytest

from gaitbot.gait import TABLE1_LEG, Trajectory, TrajectoryFileError, generate_walk

HEADER = ("t_s,hip_pitch_left_deg,knee_pitch_left_deg,ankle_pitch_left_deg,"
          "hip_pitch_right_deg,knee_pitch_right_deg,ankle_pitch_right_deg,root_x_m,root_y_m")
"""Format 1: the six pitch joints, root_y_m the height (files written before the 3D format still load)."""
HEADER_V2 = ("t_s,hip_pitch_left_deg,knee_pitch_left_deg,ankle_pitch_left_deg,"
             "hip_pitch_right_deg,knee_pitch_right_deg,ankle_pitch_right_deg,root_x_m,root_y_m,root_z_m")


@pytest.fixture(scope="module")
def walk():
    return generate_walk(TABLE1_LEG, [0.3, 0.5, 0.2])


def test_csv_round_trip(walk, tmp_path):
    path = tmp_path / "walk.csv"
    walk.save(path)
    lines = path.read_text().splitlines()
    assert lines[0] == "# gaitbot trajectory 2"
    assert lines[1] == HEADER_V2
    assert len(lines) == len(walk) + 2
    # the second row is the second frame, angles in degrees; the root in 3D with y = 0 (a planar walk)
    row = [float(x) for x in lines[3].split(",")]
    assert row[8] == 0.0 and row[9] == pytest.approx(walk.root_xz_m[1, 1], rel=1e-8)
    assert row[0] == pytest.approx(walk.t_s[1], rel=1e-8)
    np.testing.assert_allclose(row[1:7], np.degrees(walk.angles_rad[1]), rtol=1e-8, atol=1e-12)
    back = Trajectory.load(path)
    assert len(back) == len(walk)
    np.testing.assert_allclose(back.t_s, walk.t_s, rtol=1e-8, atol=1e-12)
    # 9 significant digits in the file: angles of at most a few tens of degrees to ~1e-7 deg
    np.testing.assert_allclose(back.angles_rad, walk.angles_rad, rtol=1e-8, atol=1e-11)
    np.testing.assert_allclose(back.root_m, walk.root_m, rtol=1e-8, atol=1e-11)


def test_npz_round_trip(walk, tmp_path):
    path = tmp_path / "walk.npz"
    walk.save(path)
    back = Trajectory.load(path)
    np.testing.assert_array_equal(back.t_s, walk.t_s)
    np.testing.assert_array_equal(back.root_m, walk.root_m)
    np.testing.assert_allclose(back.angles_rad, walk.angles_rad, rtol=1e-15, atol=1e-15)
    assert len(back.heel_strikes) == len(walk.heel_strikes)
    for a, b in zip(back.heel_strikes, walk.heel_strikes):
        assert (a.leg, a.t_s, a.x_m) == (b.leg, b.t_s, b.x_m)


def test_csv_columns_found_by_name(walk, tmp_path):
    """A file whose columns come in another order reads the same (columns are found by their header)."""
    table = np.column_stack([walk.t_s, np.degrees(walk.angles_rad), walk.root_xz_m])
    names = HEADER.split(",")
    order = [8, 0, 3, 1, 2, 7, 4, 5, 6]
    path = tmp_path / "shuffled.csv"
    with open(path, "w") as f:
        f.write(",".join(names[i] for i in order) + "\n")
        np.savetxt(f, table[:, order], delimiter=",", fmt="%.12g")
    back = Trajectory.load(path)
    np.testing.assert_allclose(back.angles_rad, walk.angles_rad, atol=1e-10)
    np.testing.assert_allclose(back.root_m, walk.root_m, atol=1e-11)


def small_csv(rows, header=HEADER) -> str:
    return header + "\n" + "\n".join(rows) + "\n"


GOOD_ROWS = ["0,1,2,3,4,5,6,0,1", "0.1,1,2,3,4,5,6,0.01,1", "0.2,1,2,3,4,5,6,0.02,1"]


def test_small_hand_file_reads(tmp_path):
    path = tmp_path / "ok.csv"
    path.write_text(small_csv(GOOD_ROWS))
    t = Trajectory.load(path)
    np.testing.assert_allclose(t.t_s, [0, 0.1, 0.2])
    np.testing.assert_allclose(t.angles_rad[0], np.radians([1, 2, 3, 4, 5, 6]))
    np.testing.assert_allclose(t.root_m[:, 0], [0, 0.01, 0.02])
    np.testing.assert_allclose(t.joint_deg("knee_pitch_right"), [5, 5, 5])


@pytest.mark.parametrize("text, needle", [
    (small_csv(GOOD_ROWS, HEADER.replace(",root_y_m", "")).replace(",1\n", "\n"), "root_y_m"),  # missing column
    (small_csv(GOOD_ROWS[:2] + ["0.2,1,2,3,4"]), "line 4"),                     # truncated row
    (small_csv(GOOD_ROWS[:2] + ["0.2,1,2,abc,4,5,6,0.02,1"]), "line 4"),        # not a number
    (small_csv([GOOD_ROWS[0], GOOD_ROWS[2], GOOD_ROWS[1]]), "t_s"),             # time goes back
    (small_csv([GOOD_ROWS[0], GOOD_ROWS[0]]), "t_s"),                           # time stands still
    ("", "empty"),                                                              # empty file
    (small_csv(GOOD_ROWS[:2] + ["0.2,1,2,nan,4,5,6,0.02,1"]), "finite"),        # nan
])
def test_bad_csv_raises_one_line(tmp_path, text, needle):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(TrajectoryFileError) as err:
        Trajectory.load(path)
    message = str(err.value)
    assert needle in message, message
    assert "\n" not in message
    assert str(path) in message


def test_missing_file_and_unknown_suffix(tmp_path):
    with pytest.raises(TrajectoryFileError, match="no such file"):
        Trajectory.load(tmp_path / "nothing.csv")
    other = tmp_path / "walk.txt"
    other.write_text(small_csv(GOOD_ROWS))
    with pytest.raises(TrajectoryFileError, match="unknown"):
        Trajectory.load(other)


def test_truncated_npz(walk, tmp_path):
    path = tmp_path / "walk.npz"
    walk.save(path)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(TrajectoryFileError):
        Trajectory.load(path)


def test_trajectory_shape_checked():
    with pytest.raises(ValueError):
        Trajectory(np.arange(3.0), np.zeros((3, 5)), np.zeros((3, 2)))
    with pytest.raises(ValueError):
        Trajectory(np.arange(3.0), np.zeros((3, 6)), np.zeros((2, 2)))
