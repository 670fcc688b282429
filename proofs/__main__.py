"""``python -m proofs``: the ``symrender`` command line (proofs/cli.py)."""

import sys

from .cli import main

sys.exit(main())
