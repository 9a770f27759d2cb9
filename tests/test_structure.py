"""Structure rules the house keeps (docs/architecture.md, issue 21), checked on the source:

* vendor differences live in the vendor facts (gaitbot/servos/) and the bus factory's class table, never
  as ``backend == "dynamixel"``-style branches elsewhere;
* short modules with one job: no module over 600 lines and no function over 80 in the rooms listed in
  SIZED_ROOMS (the bus, the emulator and the vendor facts; the lead widens it to all of gaitbot/).
"""

from __future__ import annotations

import ast
import re

import pytest

from helpers import REPO_ROOT

PACKAGE = REPO_ROOT / "gaitbot"
#: Where a comparison with a vendor's name may stand: the vendor facts and the bus factory.
VENDOR_BRANCHES_ALLOWED = ("servos/", "bus/factory.py")
#: ``backend == "dynamixel"``, ``model.family != 'feetech'``, ``"feetech" == backend`` ...
VENDOR_BRANCH = re.compile(r"""\b(backend|family)\s*[!=]=\s*["']|["'](dynamixel|feetech)["']\s*[!=]=""")
SIZED_ROOMS = ("bus", "emulator", "servos")
MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 80


def _modules(rooms=None):
    for path in sorted(PACKAGE.rglob("*.py")):
        relative = path.relative_to(PACKAGE).as_posix()
        if rooms is None or relative.split("/")[0] in rooms:
            yield relative, path


def test_no_vendor_branches_outside_the_vendor_facts_and_the_factory():
    found = []
    for relative, path in _modules():
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


@pytest.mark.parametrize("relative, path", list(_modules(SIZED_ROOMS)), ids=lambda v: str(v))
def test_modules_and_functions_are_short(relative, path):
    source = path.read_text()
    lines = source.count("\n")
    assert lines <= MAX_MODULE_LINES, f"gaitbot/{relative}: {lines} lines (at most {MAX_MODULE_LINES})"
    long = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            length = node.end_lineno - node.lineno + 1
            if length > MAX_FUNCTION_LINES:
                long.append(f"{node.name} ({length} lines, line {node.lineno})")
    assert not long, f"gaitbot/{relative}: functions over {MAX_FUNCTION_LINES} lines: {', '.join(long)}"
