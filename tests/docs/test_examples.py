"""Every command the README and the docs pages show runs, in a temporary folder, and exits as the text says
(the rules: tests/doc_examples.py); so do the examples of every command's ``--help``."""

from __future__ import annotations

import re

import pytest

from doc_examples import LANGUAGES, Command, fenced_blocks, page_commands, prepare_folder, run_command
from gaitbot.app.cli import build_parser
from gaitbot.app.help import COMMAND_HELP, EPILOG
from helpers import REPO_ROOT

PAGES = [REPO_ROOT / "README.md", *sorted((REPO_ROOT / "docs").glob("*.md"))]
WITH_COMMANDS = [p for p in PAGES if page_commands(p)]


def run_in_order(commands, folder):
    """Run commands one after the other (later ones use the files of earlier ones); stop at the first that
    does not do what the text says."""
    ran = 0
    for command in commands:
        outcome = run_command(command, folder, folder / "emulator-goals.jsonl")
        if outcome is None:
            continue
        ran += 1
        assert outcome.problem() is None, outcome.describe()
    return ran


@pytest.mark.slow
@pytest.mark.parametrize("page", WITH_COMMANDS, ids=lambda p: p.name)
def test_the_commands_of_a_page_do_what_it_says(page, tmp_path):
    prepare_folder(tmp_path)
    assert run_in_order(page_commands(page), tmp_path) > 0


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_code_is_in_fenced_blocks_of_known_kinds(page):
    """An indented block would hide a command from the test above; so would a block of another language."""
    lines = page.read_text().splitlines()
    fenced = set()
    for first, language, body in fenced_blocks(page):
        assert language in LANGUAGES, f"{page.name}:{first - 1}: ```{language}: mark blocks sh, text, toml or json"
        fenced.update(range(first, first + len(body)))
    for number, (before, line) in enumerate(zip([""] + lines, lines), start=1):
        if number not in fenced and line.startswith("    ") and not before.strip():
            assert re.match(r"\s*([-*]|\d+\.)\s", before) or before.strip(), \
                f"{page.name}:{number}: an indented code block; fence it (```sh or ```text)"


def help_examples():
    top = [line.split("$ ", 1)[1] for line in EPILOG.splitlines() if "$ " in line]
    return {"gaitbot": top, **{name: list(text.examples) for name, text in COMMAND_HELP.items()}}


#: The commands whose ``--help`` examples run in the quick loop (a second or so each); the others plan, simulate
#: or fit for seconds each, and are slow like the pages' commands.
QUICK_HELP = ("calibrate", "record", "scan", "setup")


@pytest.mark.parametrize("name", [n if n in QUICK_HELP else pytest.param(n, marks=pytest.mark.slow)
                                  for n in sorted(help_examples())])
def test_help_examples_run(name, tmp_path):
    prepare_folder(tmp_path)
    commands = [Command(f"gaitbot {name} --help", 0, line) for line in help_examples()[name]]
    assert run_in_order(commands, tmp_path) == len(commands)


def _parsers():
    parser = build_parser()
    return {"gaitbot": parser, **parser.commands}


@pytest.mark.parametrize("name", sorted(_parsers()))
def test_help_describes_the_command_gives_an_example_and_explains_every_option(name):
    parser = _parsers()[name]
    text = parser.format_help()
    assert parser.description and len(parser.description) > 40, name
    assert "examples:\n  $ gaitbot " in text, name
    for action in parser._actions:
        if action.option_strings or action.dest not in ("command", "eigen_command"):
            assert action.help, f"gaitbot {name} {'/'.join(action.option_strings) or action.dest}: no help text"
