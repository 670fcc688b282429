"""lab/seed_errata.py: what each erratum counts, on inputs whose answer is known without it.

The errata's measurements run on the draft's scene (verify/test_errata.py checks that each
defect is there); here their counting rules are held to small planted cases: which
(pixel, light) pairs the draft's rule would light past the terminator, and on which spheres
the ungated lobe is counted.
"""

from types import SimpleNamespace

import numpy as np
import pytest

from lab import seed_errata
from renderer import Scene
from renderer.render import BACKGROUND, SPHERE_A, SPHERE_B


def test_a_pair_in_a_cast_shadow_does_not_leak(monkeypatch):
    """The draft's rule lights a pair past the terminator only where its own cast-shadow test lets the light
    through: of four pairs whose geometric normal faces away from the light, the one behind sphere B and the
    one whose bumped normal faces away too do not count."""
    away, bumped = np.full(4, -0.5), np.array([0.3, 0.2, 0.4, -0.1])
    cast = np.array([False, True, False, False])

    def light_terms(scene, size):
        return [(scene.lights[0], away, bumped, cast)]
    monkeypatch.setattr(seed_errata, "_light_terms", light_terms)
    m = seed_errata._terminator_leak(size=8)
    assert (m["leak_pixels_default"], m["leak_pixels_beta_1_5"]) == (2, 2)


