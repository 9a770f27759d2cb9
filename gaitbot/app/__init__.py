"""The app room: the command line. The only package that sees argparse; it wires the rooms together.

``entry`` (the program's entry point: signals first), ``cli`` (the parser and main, exit statuses), one
module per command (``plan``, ``generate``, ``plot``, ``walk``, ``check``, ``eigen``, ``record``, ``scan``,
``setup``, ``calibrate``), each adding its own sub-parser, the option groups they share (``arguments``),
reading the options (``options``: robot loading, ``--rate`` and ``--reply-timeout-ms`` checks, the leg,
the steps), one plan from the walk options whatever the gait source (``planned_walk``), the hardware
(``hardware``: the serial port) and the servo emulator's command line (``emulator``).
"""
