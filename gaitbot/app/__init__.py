"""The app room: the command line. The only package that sees argparse; it wires the rooms together.

``cli`` (the parser and main), one module per command (``plan``, ``generate``, ``plot``, ``walk``,
``check``, ``eigen``, ``record``, ``scan``, ``setup``, ``calibrate``), the options they share (``options``:
robot loading,
``--rate`` and ``--reply-timeout-ms`` checks, the leg, the steps), the walk inputs (``walks``), the
hardware (``hardware``: the serial port) and the servo emulator's command line (``emulator``).
"""
