"""``--foxglove [HOST:PORT]``: the walk's channels live on the Foxglove SDK's WebSocket server, and the Teleop
panel's Twists in (gaitbot.view.teleop).

The server (``foxglove-sdk``) runs on its own threads: ``Channel.log`` only queues a message for each
subscribed client (a slow client loses its oldest messages, never the walk its frame). It listens on
127.0.0.1:8765 unless told otherwise; any other address lets whoever reaches it watch the robot and steer it,
so it is said on stderr (docs/live-view.md).
"""

from __future__ import annotations

import sys
import threading

from gaitbot.errors import UserError
from gaitbot.view.channels import STATIC_CHANNELS
from gaitbot.view.ros2_messages import schema_text
from gaitbot.view.telemetry import NEEDS_VIEW_EXTRA
from gaitbot.view.teleop import TeleopInbox

DEFAULT_HOST, DEFAULT_PORT = "127.0.0.1", 8765  # the SDK's own default port
LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1")


class ViewOptionError(UserError, ValueError):
    """A --foxglove or --mcap argument that cannot be used."""


def import_foxglove():
    try:
        import foxglove
        from foxglove.websocket import Capability
    except ImportError:
        raise ImportError(f"--foxglove {NEEDS_VIEW_EXTRA}") from None
    return foxglove, Capability


def _listener(foxglove, inbox: TeleopInbox, static_wanted: threading.Event):
    """A ServerListener handing client channels and messages to the inbox, and asking for the static channels
    again when a client subscribes to one (runs on the server's thread)."""

    class Listener(foxglove.websocket.ServerListener):
        def on_subscribe(self, client, channel) -> None:
            if channel.topic in STATIC_CHANNELS:
                static_wanted.set()

        def on_client_advertise(self, client, channel) -> None:
            inbox.advertise(client.id, channel.id, channel.topic, channel.encoding, channel.schema_name)

        def on_client_unadvertise(self, client, client_channel_id: int) -> None:
            inbox.unadvertise(client.id, client_channel_id)

        def on_message_data(self, client, client_channel_id: int, data: bytes) -> None:
            inbox.message(client.id, client_channel_id, data)

    return Listener()


class FoxgloveSink:
    """A running Foxglove WebSocket server with a channel per topic (ROS 2 CDR, ``ros2msg`` schemas)."""

    def __init__(self, host: str = DEFAULT_HOST, port: int = DEFAULT_PORT, inbox: TeleopInbox | None = None,
                 warn=lambda line: print(line, file=sys.stderr)) -> None:
        foxglove, capability = import_foxglove()
        self._foxglove = foxglove
        self.inbox = inbox if inbox is not None else TeleopInbox()
        if host not in LOCAL_HOSTS:
            warn(f"warning: --foxglove listens on {host}:{port}: anyone who can reach it sees the robot and can steer it")
        self.context = foxglove.Context()
        self.static_wanted = threading.Event()  # a client subscribed to a static channel: send them at the next frame
        try:
            self.server = foxglove.start_server(
                name="gaitbot", host=host, port=port, capabilities=[capability.ClientPublish],
                supported_encodings=["json"], server_listener=_listener(foxglove, self.inbox, self.static_wanted), context=self.context)
        except Exception as exc:  # noqa: BLE001 - the SDK's error (a port in use) in one line
            raise ViewOptionError(f"--foxglove {host}:{port}: cannot start the server: {exc}") from None
        self.host = host
        self.port = self.server.port
        self.label = f"--foxglove {host}:{self.port}"
        self._channels: dict = {}
        self.closing_note = ""
        self.repeats_static = True  # a client may connect at any time: /tf_static and /robot_description again

    def channel(self, topic: str, type_name: str):
        channel = self._channels.get(topic)
        if channel is None:
            schema = self._foxglove.Schema(name=type_name, encoding="ros2msg", data=schema_text(type_name).encode())
            channel = self._foxglove.Channel(topic, schema=schema, message_encoding="cdr", context=self.context)
            self._channels[topic] = channel
        return channel

    def write(self, topic: str, type_name: str, data: bytes, log_time_ns: int) -> None:
        self.channel(topic, type_name).log(data, log_time=log_time_ns)

    def close(self) -> None:
        if self.server is not None:
            self.server.stop()
            self.server = None
