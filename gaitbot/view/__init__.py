"""The view room: a walk's telemetry out (an MCAP log, a live Foxglove server) and teleop in.

A walk or drive session calls one observer once a frame with a :class:`~gaitbot.view.telemetry.FrameTelemetry`
(the record of that frame); :mod:`gaitbot.view.mcap_log` and :mod:`gaitbot.view.live` turn it into ROS 2
messages (CDR, standard message types: docs/live-view.md), and :mod:`gaitbot.view.teleop` turns Foxglove's
Teleop panel into a ``drive`` command source. The libraries (``mcap``, ``mcap-ros2-support``,
``foxglove-sdk``) are the optional extra ``gaitbot[view]``, imported only on these paths.
"""
