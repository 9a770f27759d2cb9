"""Live command sources for ``gaitbot drive``: the terminal's keyboard, a gamepad (evdev), UDP datagrams and
a timed commands file. Each is polled once a frame without blocking and answers with the command in force
(docs/driving.md). A new input device is one module here with a ``poll(now_s)`` method and one entry in
``open_source``.
"""
