"""Renderer of the Chapter-9 scene (two spheres, two point lights, a checker
floor, bump-mapped sphere A) with a numeric (central difference) and a
symbolic (exact gradient) pipeline: one per-pixel kernel compiled with numba
(`renderer.kernel`), its formulas generated from the sympy objects of
`renderer.formulas`.

Public API::

    from renderer import Scene, render
    frame = render(Scene(), 256, 256, gradient="exact")
"""

from .ledger import Ledger, compare, to_srgb
from .render import CHAMBER_NAMES, GRADIENTS, Frame, GBuffer, gbuffer, render
from .scene import BUMPS, HEIGHT_FIELDS, MODELS, PointLight, Scene
from .sweep import Sweep, sweep

__all__ = [
    "Scene", "PointLight", "render", "Frame", "GBuffer", "gbuffer", "Ledger", "compare", "to_srgb",
    "GRADIENTS", "HEIGHT_FIELDS", "MODELS", "BUMPS", "CHAMBER_NAMES", "Sweep", "sweep",
]
