"""Issue 26 item 8: every array's header (kind and size) is checked before any array is read, whatever its name:
a 1 MB file declaring a 1 GB text or raw array is refused at once, within bounded memory."""

from __future__ import annotations

import io
import zipfile

import numpy as np
import pytest

import helpers
from gaitbot.gait.eigen.model import is_model_file
from gaitbot.gait.npz_file import NpzProblem, read_npz
from gaitbot.gait.trajectory import Trajectory


def npy_claiming(dtype: str, shape: tuple, payload: bytes) -> bytes:
    """A .npy member whose header claims ``shape`` of ``dtype`` and holds only ``payload``."""
    out = io.BytesIO()
    np.lib.format.write_array_header_1_0(out, {"descr": dtype, "fortran_order": False, "shape": shape})
    return out.getvalue() + payload


def hostile_npz(path, name: str, dtype: str, shape: tuple) -> None:
    """A valid small trajectory plus one array ``name`` claiming far more than the file holds (1 MB of zeros:
    deflated, the probe's 1 MB file of a 1 GB array)."""
    good = io.BytesIO()
    np.savez(good, format_version=np.array(2), t_s=np.arange(3) / 60, angles_deg=np.zeros((3, 6)),
             joints=np.array(["hip_pitch_left", "knee_pitch_left", "ankle_pitch_left", "hip_pitch_right",
                              "knee_pitch_right", "ankle_pitch_right"]), root_m=np.zeros((3, 3)))
    with zipfile.ZipFile(io.BytesIO(good.getvalue())) as src, zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as dst:
        dst.writestr(f"{name}.npy", npy_claiming(dtype, shape, bytes(1_000_000)))  # first: read before the rest
        for member in src.namelist():
            if member != f"{name}.npy":
                dst.writestr(member, src.read(member))


@pytest.mark.parametrize("name, dtype, shape", [
    ("aaa_notes", "<U250000", (1000,)),     # 1 GB of text, an array the readers do not even want
    ("angles_deg", "|V1000000", (1000,)),   # 1 GB of raw records where the angles should be
    ("root_m", "<f8", (125_000_000,)),      # 1 GB of floats (beyond 20 M elements)
])
def test_a_small_file_declaring_a_huge_array_is_refused_by_its_header(tmp_path, monkeypatch, name, dtype, shape):
    path = tmp_path / "w.npz"
    hostile_npz(path, name, dtype, shape)
    assert path.stat().st_size < 2_000_000
    with pytest.raises(NpzProblem, match=repr(name)):
        read_npz(path)
    monkeypatch.setattr(helpers, "MEMORY_HEADROOM", 700 * 2**20)  # less than the 1 GB the header claims
    result = helpers.isolated(Trajectory.load, path, bound_s=20)
    helpers.assert_reader_behaves(result, path)
    assert result["outcome"] == "raised" and name in result["message"], result
    assert not is_model_file(path)


def test_the_element_bound_counts_bytes_too(tmp_path):
    """Text of a name's length passes; longer text elements are refused on the header."""
    path = tmp_path / "w.npz"
    hostile_npz(path, "label", "<U300", (10,))
    with pytest.raises(NpzProblem, match="characters"):
        read_npz(path)
