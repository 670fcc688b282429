"""Entry point of a render worker process: ``python -m renderer._worker SOCK MEM PIXELS``.

Started by `renderer.workers` (see there), not by hand.
"""

import sys

from renderer.workers import _serve

if __name__ == "__main__":
    _serve(int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]))
