"""Structure rules the house keeps (docs/architecture.md, Habits), checked on the source:

* vendor differences live in the vendor facts (gaitbot/servos/) and the bus factory's class table, never
  as ``backend == "dynamixel"``-style branches elsewhere;
* short modules with one job: no module over 600 lines and no function over 80 anywhere in gaitbot/. A long
  function or module is split by what it does, never excused here.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from helpers import REPO_ROOT

PACKAGE = REPO_ROOT / "gaitbot"
MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 80
#: Where a comparison with a vendor's name may stand: the vendor facts and the bus factory.
VENDOR_BRANCHES_ALLOWED = ("servos/", "bus/factory.py")
#: ``backend == "dynamixel"``, ``model.family != 'feetech'``, ``"feetech" == backend`` ...
VENDOR_BRANCH = re.compile(r"""\b(backend|family)\s*[!=]=\s*["']|["'](dynamixel|feetech)["']\s*[!=]=""")


def modules() -> list[Path]:
    return sorted(PACKAGE.rglob("*.py"))


def long_functions(path: Path) -> list[str]:
    """Every function or method of the module longer than MAX_FUNCTION_LINES (its def line to its last line,
    docstring included, decorators not), as ``name (N lines)``."""
    tree = ast.parse(path.read_text(), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            lines = node.end_lineno - node.lineno + 1
            if lines > MAX_FUNCTION_LINES:
                found.append(f"{node.name} ({lines} lines, line {node.lineno})")
    return found


def test_the_package_has_modules():
    assert len(modules()) > 100  # the glob finds the package, not an empty folder


@pytest.mark.parametrize("path", modules(), ids=lambda p: str(p.relative_to(REPO_ROOT)))
def test_no_module_over_600_lines_and_no_function_over_80(path):
    lines = len(path.read_text().splitlines())
    assert lines <= MAX_MODULE_LINES, f"{path.relative_to(REPO_ROOT)}: {lines} lines"
    assert long_functions(path) == [], path.relative_to(REPO_ROOT)


def test_the_function_measure_counts_what_it_should(tmp_path):
    """An independent check of the measure: a function of exactly 81 lines is found, one of 80 is not."""
    body = "\n".join(f"    x{i} = {i}" for i in range(79))
    (tmp_path / "ok.py").write_text(f"def ok():\n{body}\n")  # def line + 79 = 80
    (tmp_path / "long.py").write_text(f"class C:\n    def long(self):\n{body}\n        return 1\n".replace("\n    x", "\n        x"))
    assert long_functions(tmp_path / "ok.py") == []
    assert long_functions(tmp_path / "long.py") == ["long (81 lines, line 2)"]


def test_no_vendor_branches_outside_the_vendor_facts_and_the_factory():
    found = []
    for path in modules():
        relative = path.relative_to(PACKAGE).as_posix()
        if relative.startswith(VENDOR_BRANCHES_ALLOWED):
            continue
        for n, line in enumerate(path.read_text().splitlines(), start=1):
            code = line.split("#", 1)[0]
            if VENDOR_BRANCH.search(code):
                found.append(f"gaitbot/{relative}:{n}: {line.strip()}")
    assert not found, "vendor branches (make them vendor-table data in gaitbot/servos/ or a transport " \
                      "subclass's override):\n" + "\n".join(found)


def test_the_rule_finds_a_vendor_branch():
    """The pattern is not vacuous: it finds the branches it is meant to find, and not a framing check."""
    assert VENDOR_BRANCH.search('if self.backend == "dynamixel" and self.protocol == 1.0:')
    assert VENDOR_BRANCH.search("lock = table.get('Lock') if model.family == 'feetech' else None")
    assert VENDOR_BRANCH.search('if "feetech" != backend:')
    assert not VENDOR_BRANCH.search('if self.framing == "v2":')
    assert not VENDOR_BRANCH.search("if model.family != bus.backend:")
