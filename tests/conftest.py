"""Shared test plumbing: this folder on the path (for helpers.py), and the emulator module for tests.

Tests mirror the packages (tests/servos, gait, robot, bus, stream, check, sim, app); helpers.py holds
what several of them use. No test imports another test file, and the emulator is imported as the
module it is (gaitbot.emulator), never loaded by file path.

The slow mark (pyproject.toml) keeps the quick loop, ``pytest -q -m "not slow"``, to a couple of minutes on
two cores: slow are the figure re-derivations and the docs' commands, long simulated and real-time walks,
videos, fuzzing, and the other robots, protocols and faults of a behaviour one case of which stays quick
(``helpers.slow_except``). Every safety path keeps a quick case: a dry-run walk, a fault's stop ramp, a
limit refusal, a signal. Expensive work several tests judge is made once (session or grouped fixtures).
"""

import os

import pytest

# Software OpenGL (Mesa's llvmpipe, what MuJoCo's offscreen renderer gets on a host without a GPU) starts a
# rasterising thread per core: one video render then takes both cores of a 2-core host and can starve the
# real-time worker (a likely cause of a CI run in which every frame of an emulator walk went out 53 ms late).
# Each test, and every command it starts, renders on its own thread instead; a user's renders keep Mesa's
# default.
os.environ.setdefault("LP_NUM_THREADS", "0")

#: Modules whose tests run against a servo emulator or a real-time clock: they go to one worker, one at a
#: time (pytest-xdist's loadgroup), since two real-time walks on a 2-core host delay replies past the SDK's
#: timeouts, which the driver rightly reports as servos answering late.
REAL_TIME_MODULES = {"test_emulator_e2e.py", "test_record_emulator.py", "test_walk_signals.py",
                     "test_session_gains.py", "test_faults_emulator.py", "test_bringup_e2e.py"}


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.path.name in REAL_TIME_MODULES:
            item.add_marker(pytest.mark.xdist_group("real-time"))
    if getattr(config.option, "loadgroup", False):  # a pytest-xdist worker, --dist loadgroup
        for item in items:
            _name_its_group(item)


def _name_its_group(item) -> None:
    """What pytest-xdist's loadgroup does on a worker (the group's name after an "@" in the test's id, which
    its scheduler reads), for the tests it left without: those whose group is added above, after its own
    hook ran, and every test under pytest 9, where its writing of the id no longer takes effect
    (pytest-xdist issue 1386), so that the groups were silently ignored."""
    names = sorted({str(m.args[0] if m.args else m.kwargs.get("name", "default"))
                    for m in item.iter_markers("xdist_group")})
    nodeid = item.nodeid
    if not names or nodeid.rfind("@") > nodeid.rfind("]"):
        return
    grouped = f"{nodeid}@{'_'.join(names)}"
    if hasattr(item, "_id"):  # pytest 9: a structured id
        from _pytest.nodes import coerce_node_id

        item._id = coerce_node_id(grouped)
    else:
        item._nodeid = grouped
