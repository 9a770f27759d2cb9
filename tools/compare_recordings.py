"""Compare bus recordings packet for packet, ignoring time stamps: the check that a refactoring of the bus
room sends byte for byte what it sent before.

    python tools/compare_recordings.py BEFORE.jsonl AFTER.jsonl [BEFORE2.jsonl AFTER2.jsonl ...]

For each pair: the headers must be equal and the packet lines (direction and bytes, in order) the same;
prints one line per pair and exits 1 at the first difference of any pair (naming the line).
"""

from __future__ import annotations

import json
import sys


def packets(path: str) -> tuple[dict, list[tuple[str, str]]]:
    with open(path, encoding="utf-8") as f:
        lines = [json.loads(line) for line in f if line.strip()]
    return lines[0], [(line["dir"], line["hex"]) for line in lines[1:]]


def compare(before: str, after: str) -> str | None:
    """None when the two recordings hold the same header and packets; else where they first differ."""
    header_a, packets_a = packets(before)
    header_b, packets_b = packets(after)
    if header_a != header_b:
        return f"headers differ: {header_a} != {header_b}"
    for n, (a, b) in enumerate(zip(packets_a, packets_b), start=2):
        if a != b:
            return f"line {n}: {a[0]} {a[1]} != {b[0]} {b[1]}"
    if len(packets_a) != len(packets_b):
        return f"{len(packets_a)} packets before, {len(packets_b)} after"
    return None


def main(argv: list[str]) -> int:
    if len(argv) < 2 or len(argv) % 2:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    status = 0
    for before, after in zip(argv[0::2], argv[1::2]):
        problem = compare(before, after)
        n = len(packets(before)[1])
        print(f"{after}: {'same ' + str(n) + ' packets as ' + before if problem is None else problem}")
        status = status or (problem is not None)
    return int(status)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
