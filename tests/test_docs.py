"""The docs hold together: the README's first screen links every page, every relative link and every
``gaitbot/...`` or ``tools/...`` path the docs name exists, and every code comment that names the walking
model's page names docs/gait-model.md."""

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
