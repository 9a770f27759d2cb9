"""The dependency policy (README.md, "Development"): pyproject.toml gives lower bounds, constraints.txt pins the
tested set, and the README's install commands and .ci/run install with it (issue 26: a MuJoCo release on the
index broke a fresh clone's tests)."""

from __future__ import annotations

import re
import sys

from helpers import REPO_ROOT

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from packaging.requirements import Requirement

PYPROJECT = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())
PINS = dict(re.findall(r"^([A-Za-z0-9][\w.-]*)==(\S+)$", (REPO_ROOT / "constraints.txt").read_text(), re.M))


def _normal(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _requirements():
    project = PYPROJECT["project"]
    extras = project["optional-dependencies"]
    for text in [*project["dependencies"], *(r for extra in ("test", "plot", "sim", "view", "ecosystem", "drive") for r in extras[extra])]:
        requirement = Requirement(text)
        if requirement.name != "gaitbot" and (requirement.marker is None or requirement.marker.evaluate()):
            yield requirement


def test_every_dependency_is_pinned_in_constraints_within_pyprojects_bounds():
    pins = {_normal(name): version for name, version in PINS.items()}
    for requirement in _requirements():
        name = _normal(requirement.name)
        assert name in pins, f"constraints.txt: no pin of {name} (python tools/constraints.py > constraints.txt)"
        assert requirement.specifier.contains(pins[name], prereleases=True), (
            f"constraints.txt: {name}=={pins[name]} is outside pyproject.toml's {requirement}")


def test_pyproject_gives_lower_bounds_only():
    """No upper bounds on an application that shares users' environments: constraints.txt holds the tested set."""
    for requirement in _requirements():
        assert all(spec.operator == ">=" for spec in requirement.specifier), f"pyproject.toml: {requirement}"


def test_the_readme_and_ci_install_the_constrained_set():
    readme = (REPO_ROOT / "README.md").read_text()
    installs = [line for line in re.findall(r"pip install [^\n&]*'\.\[[\w,]+\]'", readme)
                if "--upgrade" not in line]  # the refresh of constraints.txt itself takes the newest
    assert len(installs) >= 2 and all("-c constraints.txt" in line for line in installs), installs
    ci = (REPO_ROOT / ".ci" / "run").read_text()
    assert "-c constraints.txt" in ci and "pytest -q" in ci
