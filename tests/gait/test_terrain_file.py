"""Terrain files: the shipped examples load; every mistake is one line naming the file and the field."""


import pytest

from gaitbot.gait.terrain.model import Terrain, TerrainError, Tread
from gaitbot.gait.terrain.course_file import TerrainFileError, load_course
from helpers import CONFIG_DIR

EXAMPLES = sorted((CONFIG_DIR / "terrain").glob("*.toml"))


def test_examples_are_shipped():
    assert {p.stem for p in EXAMPLES} >= {"kerb", "stairs", "ditch"}


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_examples_load(path):
    course = load_course(path)
    assert course.end_m > course.start_m
    assert course.terrain.treads


def write(tmp_path, text):
    path = tmp_path / "course.toml"
    path.write_text(text)
    return path


GOOD = """
[course]
start_m = 0.0
end_m = 1.0
"""


@pytest.mark.parametrize("body, field, words", [
    ("[[tread]]\nstart_m = 0.2\nlength_m = 0.3\nheight_m = 0.02\n[[tread]]\nstart_m = 0.4\nlength_m = 0.2\n"
     "height_m = 0.04\n", "tread[2].start_m", "overlaps tread 1"),
    ("[[tread]]\nstart_m = 0.2\nlength_m = 0.2\nheight_m = 0.02\n[[tread]]\nstart_m = 0.4005\nlength_m = 0.2\n"
     "height_m = 0.04\n", "tread[2].start_m", "gap"),
    ("[[tread]]\nstart_m = 0.2\nlength_m = -0.1\nheight_m = 0.02\n", "tread[1].length_m", "positive"),
    ("[[tread]]\nstart_m = 0.2\nlength_m = 0.1\n", "tread[1].height_m", "missing"),
    ("[[tread]]\nstart_m = 0.2\nlenght_m = 0.1\nheight_m = 0.0\n", "tread[1].lenght_m", "length_m"),
    ("[[tread]]\nstart_m = 0.2\nlength_m = 'long'\nheight_m = 0.0\n", "tread[1].length_m", "number"),
    ("[search]\nweights = [1, 2]\n", "search.weights", "3 numbers"),
    ("[search]\nweights = [0, 0, 0]\n", "search.weights", "positive"),
])
def test_mistakes_name_file_and_field(tmp_path, body, field, words):
    path = write(tmp_path, GOOD + body)
    with pytest.raises(TerrainFileError) as err:
        load_course(path)
    message = str(err.value)
    assert message.startswith(f"{path}: {field}: ")
    assert words in message
    assert "\n" not in message


def test_course_fields_checked(tmp_path):
    with pytest.raises(TerrainFileError, match=r"course.end_m: .*beyond start_m"):
        load_course(write(tmp_path, "[course]\nstart_m = 1.0\nend_m = 0.5\n"))
    with pytest.raises(TerrainFileError, match=r"file: not valid TOML"):
        load_course(write(tmp_path, "[course\n"))
    with pytest.raises(TerrainFileError, match=r"file: no such file"):
        load_course(tmp_path / "missing.toml")


def test_course_table_is_optional_and_its_extent_follows_from_the_treads(tmp_path):
    """Without [course]: start at 0, end 0.3 m past the far end of the last tread (END_PAST_TREADS_M), margin 0.01."""
    treads = "[[tread]]\nstart_m = 0.4\nlength_m = 0.5\nheight_m = 0.03\n[[tread]]\nstart_m = 0.9\nlength_m = 0.2\n" \
             "height_m = 0.0\n"
    course = load_course(write(tmp_path, treads))
    assert (course.start_m, course.end_m, course.margin_m) == (0.0, pytest.approx(1.4), 0.01)
    course = load_course(write(tmp_path, "[course]\nend_m = 0.8\n" + treads))
    assert (course.start_m, course.end_m) == (0.0, 0.8)
    course = load_course(write(tmp_path, "[course]\nstart_m = 0.1\n" + treads))
    assert (course.start_m, course.end_m) == (0.1, pytest.approx(1.4))


def test_a_course_without_course_table_walks(tmp_path, capsys):
    from helpers import run_cli

    path = write(tmp_path, "[[tread]]\nstart_m = 0.4\nlength_m = 0.6\nheight_m = 0.02\n")
    code, out, err = run_cli(capsys, "plan", "--terrain", path, "--json")
    assert code == 0, err
    assert '"n_terrain_steps"' in out


def test_profile_heights_and_edges():
    terrain = Terrain((Tread(0.5, 0.2, 0.03), Tread(0.7, 0.2, 0.06), Tread(1.2, 0.1, -0.05)))
    assert terrain.height_at([0.0, 0.6, 0.8, 1.0, 1.25, 2.0]).tolist() == [0.0, 0.03, 0.06, 0.0, -0.05, 0.0]
    # at an edge the higher surface counts
    assert terrain.height_at([0.5, 0.7, 0.9, 1.2]).tolist() == [0.03, 0.06, 0.06, 0.0]
    assert [e[0] for e in terrain.edges()] == pytest.approx([0.5, 0.7, 0.9, 1.2, 1.3])
    assert terrain.level_between(0.55, 0.65) and not terrain.level_between(0.55, 0.75)
    with pytest.raises(TerrainError):
        Terrain((Tread(0.5, 0.2, 0.03), Tread(0.6, 0.2, 0.06)))
