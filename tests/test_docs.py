"""The docs hold together: the README's first screen links every page, every relative link and every
``gaitbot/...`` or ``tools/...`` path the docs name exists, every code comment that names the walking
model's page names docs/gait-model.md, the command line's table lists every command, and the docs' index
sorts every page into one kind."""

from __future__ import annotations

import re

from helpers import REPO_ROOT

DOCS = sorted((REPO_ROOT / "docs").glob("*.md"))
PAGES = [REPO_ROOT / "README.md", *DOCS]


def test_readme_is_one_screen_and_links_every_page():
    readme = (REPO_ROOT / "README.md").read_text()
    assert readme.count("\n") <= 120
    for page in DOCS:
        assert f"(docs/{page.name})" in readme, page.name


def test_relative_links_resolve():
    for page in PAGES:
        for target in re.findall(r"\]\(([^)#:]+)(?:#[^)]*)?\)", page.read_text()):
            assert (page.parent / target).exists(), (page.name, target)


def test_named_paths_exist():
    for page in PAGES:
        for path in re.findall(r"`((?:gaitbot|tools|tests|config)/[\w./-]*)`", page.read_text()):
            assert (REPO_ROOT / path.rstrip("/")).exists(), (page.name, path)


def test_comments_name_the_model_page_by_its_path():
    for source in [*(REPO_ROOT / "gaitbot").rglob("*.py"), *(REPO_ROOT / "tests").rglob("*.py")]:
        for line in source.read_text().splitlines():
            if "gait-model.md" in line and source.name != "test_docs.py":
                assert "docs/gait-model.md" in line, (source, line)
    assert (REPO_ROOT / "docs" / "gait-model.md").is_file()


def _table_commands(page_text: str) -> set[str]:
    """The commands named in the first column of docs/command-line.md's command table."""
    table = page_text.split("| command | what it does | needs |", 1)[1].split("\n\n", 1)[0]
    names = set()
    for row in table.splitlines()[2:]:
        first_cell = row.split("|")[1]
        names.update(re.findall(r"`gaitbot ([a-z]+(?: [a-z]+)?)`", first_cell))
    return names


def test_the_command_table_lists_every_command():
    """docs/command-line.md's table is every command: each command and subcommand the parser has (the
    leaves: ``eigen fit``, not ``eigen``), and nothing the parser does not have."""
    from gaitbot.app.cli import build_parser

    commands = set(build_parser().commands)
    leaves = {name for name in commands if not any(other.startswith(name + " ") for other in commands)}
    listed = _table_commands((REPO_ROOT / "docs" / "command-line.md").read_text())
    assert listed == leaves, (sorted(leaves - listed), sorted(listed - leaves))


def test_the_index_sorts_every_page_by_kind():
    """docs/README.md links every other page once, under one of the four kinds (tutorial, how-to,
    reference, explanation)."""
    index = (REPO_ROOT / "docs" / "README.md").read_text()
    sections = re.split(r"^## ", index, flags=re.M)[1:]
    assert len(sections) == 4, [s.splitlines()[0] for s in sections]
    linked = [target for section in sections for target in re.findall(r"\]\(([\w-]+\.md)\)", section)]
    assert sorted(linked) == sorted(p.name for p in DOCS if p.name != "README.md")


def test_papers_are_named_by_their_authors_and_no_issue_numbers_reach_a_user():
    """A reader cannot look up "seed 003" or "issue 15": the papers go by their authors (docs/gait-model.md,
    "The papers"), and the project's own tracker numbers stay out of what a user reads or runs."""
    unreadable = re.compile(r"\bseeds? 00\d|\bissue #?\d", re.I)
    sources = [*PAGES, *(REPO_ROOT / "gaitbot").rglob("*.py"), *(REPO_ROOT / "tools").glob("*.py")]
    found = [f"{path.relative_to(REPO_ROOT)}:{number}: {line.strip()}" for path in sources
             for number, line in enumerate(path.read_text().splitlines(), start=1) if unreadable.search(line)]
    assert not found, "\n".join(found)


MAX_PAGE_WORDS = 3500
"""A page a reader finishes in one sitting: about a quarter of an hour at a technical reader's pace. A page
that grows past it splits by what its reader needs (docs/README.md's kinds)."""


def test_each_page_is_read_in_one_sitting():
    long_pages = {page.name: len(page.read_text().split()) for page in PAGES}
    assert all(words <= MAX_PAGE_WORDS for words in long_pages.values()), \
        {name: words for name, words in long_pages.items() if words > MAX_PAGE_WORDS}
