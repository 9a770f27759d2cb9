"""``python -m gaitbot``: the same as the ``gaitbot`` command (gaitbot.app.entry)."""

import sys

from gaitbot.app.entry import main

sys.exit(main())
