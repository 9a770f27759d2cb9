"""The docs' measured figures are what their scripts print today: each figure region (tools/figures.py) is
compared with a fresh run of the command it names, so a figure whose source changed fails here."""

from __future__ import annotations

import re
import sys

import pytest

from helpers import REPO_ROOT

sys.path.insert(0, str(REPO_ROOT / "tools"))
from figures import PAGES, PICTURES, difference, regions, run_figure_command  # noqa: E402

REGIONS = regions()
COMMANDS = sorted({r.command for r in REGIONS})


def test_the_docs_hold_figures():
    assert len(REGIONS) >= 8 and len(COMMANDS) >= 4


@pytest.mark.slow
@pytest.mark.parametrize("command", COMMANDS)
def test_documented_figures_are_what_a_fresh_run_prints(command):
    fresh = run_figure_command(command)
    problems = []
    for region in (r for r in REGIONS if r.command == command):
        if region.name not in fresh:
            problems.append(f"{region.page.name}: {region.name}: not printed by {command}")
            continue
        why = difference(region.text, fresh[region.name])
        if why:
            problems.append(f"{region.page.name}: figure {region.name} is stale: {why} "
                            f"(python tools/figures.py --only {region.name} rewrites it)")
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize("region", REGIONS, ids=lambda r: r.name)
def test_each_figure_names_its_script_where_a_reader_sees_it(region):
    visible = re.sub(r"<!--.*?-->", "", region.page.read_text(), flags=re.S)
    script = next(word for word in region.command.split() if word.startswith("tools/"))
    assert f"`python {script}" in visible, f"{region.page.name}: say which script prints figure {region.name}"


def test_a_changed_figure_is_a_difference_and_rounding_is_not():
    table = "| default | 6 | 0.15 to 0.30 deg | within 1.9% |"
    assert difference(table, table) is None
    assert difference(table, table.replace("0.30", "0.31")) is None  # one unit of the last printed digit
    assert "0.30 in the docs, 0.32 now" in difference(table, table.replace("0.30", "0.32"))
    assert difference(table, table.replace("1.9%", "3.1%")) is not None
    assert difference(table, table.replace("default", "paper")) is not None
    assert difference("axes 6", "axes 6 and 7") is not None


def test_every_picture_in_the_docs_is_drawn_by_figures_py():
    shown = {(page.parent / target).resolve() for page in PAGES
             for target in re.findall(r"!\[[^]]*\]\(([^)]+\.png)\)", page.read_text())}
    drawn = {(REPO_ROOT / picture).resolve() for picture in PICTURES}
    assert shown == drawn
    assert all(path.is_file() for path in drawn)
