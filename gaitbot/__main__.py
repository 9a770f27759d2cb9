"""``python -m gaitbot``: the same as the ``gaitbot`` command."""

import sys

from gaitbot.app.cli import main

sys.exit(main())
