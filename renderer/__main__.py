"""``python -m renderer``: the ``symrender`` command line (renderer/cli.py)."""

import sys

from .cli import main

sys.exit(main())
