"""Vectorized numpy renderer of the Chapter-9 scene (two spheres, two point
lights, checker floor, bump-mapped sphere A) with a numeric (central
difference) and a symbolic (exact gradient) pipeline.

Public API (DESIGN.md)::

    from renderer import Scene, PointLight, render
    frame = render(Scene(), width=256, height=256, gradient="exact")
"""

from .ledger import Ledger, compare, to_srgb
from .render import CHAMBER_NAMES, GRADIENTS, Frame, GBuffer, gbuffer, render
from .scene import BUMPS, HEIGHT_FIELDS, MODELS, PointLight, Scene
from .sweep import Sweep, sweep

__all__ = [
    "Scene", "PointLight", "render", "Frame", "GBuffer", "gbuffer", "Ledger", "compare", "to_srgb",
    "GRADIENTS", "HEIGHT_FIELDS", "MODELS", "BUMPS", "CHAMBER_NAMES", "Sweep", "sweep",
]
