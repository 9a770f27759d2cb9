"""The channels of an MCAP file: topic, message type, encoding, message count and rate (docs/live-view.md).

    python tools/mcap_channels.py walk.mcap

Read with the ``mcap`` library's reader (the ``view`` extra), as any MCAP tool would: a quick look at a log
that ``gaitbot walk --mcap`` wrote, without Foxglove or ROS.
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file", help="an .mcap file")
    args = parser.parse_args(argv)
    try:
        from mcap.reader import make_reader
    except ImportError:
        print("mcap_channels: needs pip install 'gaitbot[view]'", file=sys.stderr)
        return 2
    times = defaultdict(list)
    try:
        with open(args.file, "rb") as f:
            reader = make_reader(f)
            profile = reader.get_header().profile
            for schema, channel, message in reader.iter_messages():
                times[(channel.topic, schema.name if schema else "", channel.message_encoding)].append(message.log_time)
    except Exception as exc:  # noqa: BLE001 - a missing file or one that is not an MCAP: one line
        print(f"mcap_channels: {args.file}: {exc}", file=sys.stderr)
        return 2
    print(f"{args.file}: profile {profile or '(none)'}, {len(times)} channels")
    for (topic, schema, encoding), stamps in sorted(times.items()):
        span_s = (stamps[-1] - stamps[0]) / 1e9
        rate = f"{(len(stamps) - 1) / span_s:5.1f} Hz" if span_s > 0 else "    -   "
        print(f"  {topic:18s} {schema:38s} {encoding:5s} {len(stamps):6d} messages  {rate}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
