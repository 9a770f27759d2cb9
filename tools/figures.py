"""The docs' figures and pictures, regenerated from the scripts that measure them (docs/figures.md).

    python tools/figures.py              # run every figure script, rewrite the docs' figures, redraw the pictures
    python tools/figures.py --check      # compare the docs with a fresh run, write nothing (exit 1: stale)
    python tools/figures.py --list       # every figure, its page and the command that prints it
    python tools/figures.py --only eigen-heldout swing-clearance    # just these

A measured figure in README.md or docs/*.md sits in a region that names the command printing it:

    <!-- figure NAME: python tools/SCRIPT.py ARGS -->
    (what the script printed)
    <!-- /figure -->

Run with ``--markdown`` added, the command prints its figures as ``<!-- figure NAME -->`` ... ``<!-- /figure -->``
blocks; this script puts each in its region. Numbers compare within one unit of their last printed digit
(a last digit may differ between machines' floating point); everything else must match exactly. A figure
measured in MuJoCo is marked ``; simulated`` after its command and compares with the SIMULATED tolerance
(docs/figures.md, "Simulated figures"): a walk is chaotic, and another CPU or MuJoCo release moves it.
tests/docs/test_figures.py runs the same comparison, so a figure whose source changed fails the tests.
Timing figures (docs/benchmarks.md) are not regions: they depend on the machine; their commands are named
beside them. Pictures are redrawn by the commands in PICTURES.
"""

from __future__ import annotations

import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
REGION = re.compile(r"<!-- figure ([\w-]+): (.+?)(; simulated)?(; long)? -->\n(.*?)<!-- /figure -->", re.S)
LONG_FIGURES_ENV = "GAITBOT_LONG_FIGURES"
"""Set to 1, the test suite also reruns the figures marked ``; long`` (minutes each; tools/figures.py --check
always does)."""
PRINTED = re.compile(r"<!-- figure ([\w-]+) -->\n(.*?)<!-- /figure -->", re.S)
NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")

EXACT_UNITS = 1
"""A figure's numbers compare within this many units of their last printed digit (floating point's last digit)."""
SIMULATED_UNITS = 20
"""A simulated figure's numbers compare within this many units of their last printed digit: drift +-2 cm when
printed to 0.1 cm, RMS +-0.2 deg when printed to 0.01 deg. tools/figure_spread.py measures how far rounding-sized
nudges to the physics move them (up to 7 units, docs/figures.md); a walk that breaks a target changes a verdict."""
FAILED = re.compile(r"\*\*no\*\*|FELL")
"""A failed or fallen walk's mark: in a simulated figure, a line failed in both texts compares up to its mark."""

#: Pictures in the docs and the commands that draw them (run in a temporary folder that links config/ and tools/).
PICTURES = {
    "docs/walk.png": ["gaitbot generate --distance 1.0 -o walk.csv",
                      "gaitbot plot walk.csv -o walk.png"],
    "docs/kerb.png": ["gaitbot generate --terrain config/terrain/kerb.toml -o kerb.csv",
                      "gaitbot plot kerb.csv --terrain config/terrain/kerb.toml -o kerb.png"],
    "docs/eigen.png": ["for s in 0.02 0.03 0.04 0.05 0.06 0.07 0.08 0.09; do gaitbot generate "
                       "--steps $s,$s,$s,$s,$s,$s -o ex_$s.npz; done",
                       "gaitbot eigen fit ex_*.npz -o model.npz",
                       "gaitbot plot model.npz -o eigen.png"],
    "docs/zero-pose.png": ["python tools/bringup_figures.py zero-pose zero-pose.png"],
    # a servo heating under load on the emulator (docs/bring-up.md): the walk stops at the stop temperature (exit 1)
    "docs/health-walk.png": ["python tools/servo_emulator.py --robot config/xl430-biped.toml --load 3:90 "
                             "--temperature 3:59 --heat-rate 4 > emulator.txt & sleep 2; "
                             "gaitbot walk --robot config/xl430-biped.toml --steps 0.05,0.05 "
                             "--port $(head -1 emulator.txt) --record heat.jsonl; kill %1; test -s heat.jsonl",
                             "python tools/bringup_figures.py health heat.jsonl health-walk.png"],
}


def _this_python_first() -> dict:
    """The environment with this Python's folder first on PATH: ``python`` and ``gaitbot`` are this install's."""
    return {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"}


@dataclass(frozen=True)
class Region:
    page: Path
    name: str
    command: str
    text: str
    simulated: bool = False
    long: bool = False
    """Marked ``; long``: its command runs for minutes (a hundred pushes, a ten-minute drive), too long for every
    test run; ``python tools/figures.py --check`` reruns it, the suite only with LONG_FIGURES_ENV=1."""

    @property
    def units(self) -> int:
        """How many units of their last printed digit this figure's numbers may move."""
        return SIMULATED_UNITS if self.simulated else EXACT_UNITS


def _in_code(text: str, position: int) -> bool:
    """True inside a fenced block (docs/figures.md shows a region's syntax in one)."""
    return text.count("\n```", 0, position) % 2 == 1


def regions(pages=PAGES) -> list[Region]:
    found = []
    for page in pages:
        text = page.read_text()
        found += [Region(page, m.group(1), m.group(2).strip(), m.group(5), bool(m.group(3)), bool(m.group(4)))
                  for m in REGION.finditer(text) if not _in_code(text, m.start())]
    return found


def run_figure_command(command: str) -> dict[str, str]:
    """Run a figure command (with ``--markdown``) from the checkout; its figures by name."""
    argv = shlex.split(command)
    if argv[0] == "python":
        argv[0] = sys.executable
    proc = subprocess.run([*argv, "--markdown"], cwd=ROOT, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{command} --markdown failed ({proc.returncode}):\n{proc.stderr[-3000:]}")
    printed = {m.group(1): m.group(2) for m in PRINTED.finditer(proc.stdout)}
    if not printed:
        raise RuntimeError(f"{command} --markdown printed no <!-- figure NAME --> block")
    return printed


def _decimals(token: str) -> int:
    mantissa = token.lower().split("e")[0]
    return len(mantissa.split(".")[1]) if "." in mantissa else 0


def _failed_lines_cut(documented: str, fresh: str) -> tuple[str, str]:
    """Both texts with every line that failed in both (``**no**``, ``FELL``) cut after its mark: what a walk
    did after it went wrong (where it fell, how far it strayed) is chaos, its verdict is not."""
    lines_a, lines_b = documented.splitlines(), fresh.splitlines()
    if len(lines_a) != len(lines_b):
        return documented, fresh
    for i, (a, b) in enumerate(zip(lines_a, lines_b)):
        mark_a, mark_b = FAILED.search(a), FAILED.search(b)
        if mark_a and mark_b and a[:mark_a.end()] == b[:mark_b.end()]:
            lines_a[i], lines_b[i] = a[:mark_a.end()], b[:mark_b.end()]
    return "\n".join(lines_a), "\n".join(lines_b)


def difference(documented: str, fresh: str, units: int = EXACT_UNITS) -> str | None:
    """None when the texts hold the same figures (numbers within ``units`` units of their last printed digit),
    else the first difference in words. ``units`` above EXACT_UNITS: a simulated figure (failed lines cut)."""
    if units > EXACT_UNITS:
        documented, fresh = _failed_lines_cut(documented, fresh)
    words_a, words_b = NUMBER.split(documented), NUMBER.split(fresh)
    nums_a, nums_b = NUMBER.findall(documented), NUMBER.findall(fresh)
    if words_a != words_b or len(nums_a) != len(nums_b):
        for line_a, line_b in zip(documented.splitlines() + [""], fresh.splitlines() + [""]):
            if NUMBER.split(line_a) != NUMBER.split(line_b) or len(NUMBER.findall(line_a)) != len(
                    NUMBER.findall(line_b)):
                return f"the text differs:\n  docs:  {line_a}\n  fresh: {line_b}"
        return "the text differs"
    for a, b in zip(nums_a, nums_b):
        unit = 10.0 ** -max(_decimals(a), _decimals(b))
        if "e" in a.lower() or "e" in b.lower():
            unit = abs(float(a)) * 1e-2
        if abs(float(a) - float(b)) > units * unit * (1 + 1e-9):
            line = next((ln for ln in fresh.splitlines() if b in ln), "")
            return f"{a} in the docs, {b} now ({line.strip()})"
    return None


def check(selected: list[Region]) -> list[str]:
    """Problems of the selected regions against a fresh run of their commands."""
    problems, cache = [], {}
    for region in selected:
        if region.command not in cache:
            cache[region.command] = run_figure_command(region.command)
        fresh = cache[region.command].get(region.name)
        if fresh is None:
            problems.append(f"{region.page.name}: figure {region.name}: {region.command} does not print it")
            continue
        why = difference(region.text, fresh, region.units)
        if why:
            problems.append(f"{region.page.name}: figure {region.name} ({region.command}): {why}")
    return problems


def rewrite(selected: list[Region]) -> int:
    """Rerun the selected regions' commands, then write their output into the pages. Every command runs before
    any page is read, so a page edited while a long figure runs keeps the edit."""
    cache: dict[str, dict[str, str]] = {}
    for region in selected:
        if region.command not in cache:
            cache[region.command] = run_figure_command(region.command)
    changed = 0
    for page in sorted({r.page for r in selected}):
        text = page.read_text()
        names = {r.name for r in selected if r.page == page}

        def fill(match):
            nonlocal changed
            name, command = match.group(1), match.group(2).strip()
            marks = (match.group(3) or "") + (match.group(4) or "")
            if name not in names or _in_code(text, match.start()):
                return match.group(0)
            fresh = cache[command][name]
            changed += fresh != match.group(5)
            return f"<!-- figure {name}: {command}{marks} -->\n{fresh}<!-- /figure -->"

        page.write_text(REGION.sub(fill, text))
    return changed


def draw_pictures(names) -> None:
    for picture, commands in PICTURES.items():
        if names and Path(picture).stem not in names and picture not in names:
            continue
        with tempfile.TemporaryDirectory() as folder:
            for name in ("config", "tools"):
                (Path(folder) / name).symlink_to(ROOT / name)
            for command in commands:
                subprocess.run(["bash", "-c", command], cwd=folder, check=True, stdout=subprocess.DEVNULL,
                               env=_this_python_first())
            shutil.copyfile(Path(folder) / Path(picture).name, ROOT / picture)
        print(f"drew {picture}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare with a fresh run, write nothing")
    parser.add_argument("--list", action="store_true", help="list the figures and their commands")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="just these figures (or pictures, by file stem)")
    args = parser.parse_args(argv)
    found = regions()
    selected = [r for r in found if not args.only or r.name in args.only]
    if args.list:
        for r in found:
            print(f"{r.page.relative_to(ROOT)}: {r.name}: {r.command}")
        for picture, commands in PICTURES.items():
            print(f"{picture}: {' && '.join(commands)}")
        return 0
    if args.check:
        problems = check(selected)
        for problem in problems:
            print(problem)
        print(f"{len(selected)} figures checked, {len(problems)} stale")
        return 1 if problems else 0
    changed = rewrite(selected)
    print(f"{len(selected)} figures, {changed} rewritten")
    draw_pictures(args.only)
    return 0


if __name__ == "__main__":
    sys.exit(main())
