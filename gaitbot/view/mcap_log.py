"""``--mcap FILE``: the walk's channels in an MCAP file (ROS 2 profile, CDR messages, ``ros2msg`` schemas),
written with the ``mcap`` library, so that ``ros2 bag info/play`` and Foxglove open it.

The file is the view of a walk, not its record: the bus recording (``--record``) stays the byte-exact
record that ``gaitbot check`` reads. Messages go into chunks in memory and reach the disk a chunk at a
time (``CHUNK_BYTES``), so a frame costs no system call.
"""

from __future__ import annotations

from pathlib import Path

from gaitbot.view.ros2_messages import schema_text
from gaitbot.view.telemetry import NEEDS_VIEW_EXTRA

CHUNK_BYTES = 256 * 1024  # about 2 s of a 12-joint walk's channels


def import_mcap_writer():
    try:
        from mcap.writer import CompressionType, Writer
    except ImportError:
        raise ImportError(f"--mcap {NEEDS_VIEW_EXTRA}") from None
    return Writer, CompressionType


class McapSink:
    """An MCAP file being written: a schema per message type and a channel per topic, registered on first use."""

    def __init__(self, path: str | Path, library: str = "gaitbot") -> None:
        writer_class, compression = import_mcap_writer()
        self.path = Path(path)
        self.label = f"--mcap {self.path}"
        self._file = open(self.path, "wb")  # noqa: SIM115 - closed in close()
        self._writer = writer_class(self._file, chunk_size=CHUNK_BYTES, compression=compression.ZSTD)
        self._writer.start(profile="ros2", library=library)
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._sequence = 0
        self.messages = 0
        self.closing_note = ""

    def _channel(self, topic: str, type_name: str) -> int:
        channel = self._channels.get(topic)
        if channel is None:
            schema = self._schemas.get(type_name)
            if schema is None:
                schema = self._writer.register_schema(type_name, "ros2msg", schema_text(type_name).encode())
                self._schemas[type_name] = schema
            channel = self._writer.register_channel(topic, "cdr", schema)
            self._channels[topic] = channel
        return channel

    def write(self, topic: str, type_name: str, data: bytes, log_time_ns: int) -> None:
        channel = self._channel(topic, type_name)
        self._writer.add_message(channel, log_time=log_time_ns, data=data, publish_time=log_time_ns,
                                 sequence=self._sequence)
        self._sequence += 1
        self.messages += 1

    def close(self) -> None:
        if self._file.closed:
            return
        try:
            self._writer.finish()
        finally:
            self._file.close()
        self.closing_note = f"mcap: {self.path} ({self.messages} messages on {len(self._channels)} channels)"
