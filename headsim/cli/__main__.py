"""``python -m headsim.cli``: the ``headsim`` command."""

import sys

from headsim.cli import main

sys.exit(main())
