"""Print the tested set of packages: every distribution gaitbot and its extras need, pinned to the version
installed here (the dependency policy: README.md, "Development").

    pip install --upgrade '.[test,plot,sim]' && pytest -q && python tools/constraints.py > constraints.txt

pyproject.toml says what gaitbot works with (lower bounds: the oldest API it uses); constraints.txt says
what was tested together. The README's commands and .ci/run install with ``-c constraints.txt``, so a new
release on the index (MuJoCo 4.0.0 was one) changes nothing until someone refreshes the file on purpose:
upgrade, run the tests, write the file, commit it with whatever the new versions needed.
"""

from __future__ import annotations

import re
import sys
from importlib import metadata

EXTRAS = ("test", "plot", "sim", "view", "ecosystem", "drive")
_NAME = re.compile(r"^\s*([A-Za-z0-9][A-Za-z0-9._-]*)(?:\[([^\]]*)\])?")


def _normal(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _wanted(requirement: str, extras: set[str]) -> tuple[str, set[str]] | None:
    """The name and extras a requirement asks for here, or None when its marker leaves it out."""
    text, _, marker = requirement.partition(";")
    if marker:
        try:
            from packaging.markers import Marker
        except ImportError:  # pragma: no cover - pip vendors packaging; setuptools ships it
            from pip._vendor.packaging.markers import Marker
        if not any(Marker(marker).evaluate({"extra": extra}) for extra in (extras or {""})):
            return None
    match = _NAME.match(text)
    return _normal(match.group(1)), {e.strip() for e in (match.group(2) or "").split(",") if e.strip()}


def closure(root: str = "gaitbot", extras: tuple[str, ...] = EXTRAS) -> dict[str, str]:
    """Every installed distribution that ``root[extras]`` needs, directly or not: name -> version."""
    found: dict[str, str] = {}
    todo = [(root, set(extras))]
    while todo:
        name, wanted_extras = todo.pop()
        dist = metadata.distribution(name)
        if name != root:
            found[_normal(dist.metadata["Name"])] = dist.version
        for requirement in dist.requires or []:
            wanted = _wanted(requirement, wanted_extras)
            if wanted and wanted[0] != root and wanted[0] not in found:
                todo.append(wanted)
    return found


def main() -> int:
    print("# The tested set: python tools/constraints.py (README.md, \"Development\"). Refreshed on purpose.")
    print(f"# Python {sys.version_info.major}.{sys.version_info.minor}; gaitbot[{','.join(EXTRAS)}]")
    for name, version in sorted(closure().items()):
        print(f"{name}=={version}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
