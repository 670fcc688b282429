"""Vectorized numpy renderer of the Chapter-9 scene (two spheres, two point
lights, checker floor, bump-mapped sphere A) with a numeric (central
difference) and a symbolic (exact gradient) pipeline.

Public API::

    from renderer import Scene, PointLight, render
    frame = render(Scene(), width=256, height=256, gradient="exact")

The public names are imported on first use (PEP 562): ``import renderer``
loads neither numpy nor sympy, so the ``symrender`` command line
(`renderer.cli`) starts at once and does its heavy imports where it handles a
Ctrl-C.  ``from renderer import Scene, render``, ``renderer.render``, the
submodules (``from renderer import fields``, ``renderer.fields``) and
``dir(renderer)`` behave as with eager imports; as before, the package
attributes ``render`` and ``sweep`` are the functions (the modules are
``importlib.import_module("renderer.render")`` and ``"renderer.sweep"``).
"""

import importlib as _importlib
import sys as _sys
import types as _types
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    # Where each lazy name comes from, as import statements that static tools
    # read: type checkers, and the book's dependency finder (book/_ext/nb_deps.py),
    # which must see that ``from renderer import Scene`` loads renderer/scene.py.
    # tests/test_interrupts.py checks that these match _EXPORTS.
    from .ledger import Ledger, compare, to_srgb
    from .render import CHAMBER_NAMES, GRADIENTS, Frame, GBuffer, gbuffer, render
    from .scene import BUMPS, HEIGHT_FIELDS, MODELS, PointLight, Scene
    from .sweep import Sweep, sweep

#: Public name -> the submodule that defines it.
_EXPORTS = {
    "Ledger": "ledger", "compare": "ledger", "to_srgb": "ledger",
    "CHAMBER_NAMES": "render", "GRADIENTS": "render", "Frame": "render", "GBuffer": "render",
    "gbuffer": "render", "render": "render",
    "BUMPS": "scene", "HEIGHT_FIELDS": "scene", "MODELS": "scene", "PointLight": "scene",
    "Scene": "scene",
    "Sweep": "sweep", "sweep": "sweep",
}
#: Submodules reachable as attributes of the package (imported on first use).
_SUBMODULES = frozenset({"cli", "detmath", "fields", "files", "geometry", "heap", "jsgen", "ledger",
                         "scene", "workers"})

__all__ = [
    "Scene", "PointLight", "render", "Frame", "GBuffer", "gbuffer", "Ledger", "compare", "to_srgb",
    "GRADIENTS", "HEIGHT_FIELDS", "MODELS", "BUMPS", "CHAMBER_NAMES", "Sweep", "sweep",
]


def __getattr__(name):
    """Import a public name (or a submodule) on first access and keep it."""
    if name in _EXPORTS:
        value = getattr(_importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    elif name in _SUBMODULES:
        value = _importlib.import_module(f"{__name__}.{name}")
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__) | _SUBMODULES)


class _Package(_types.ModuleType):
    """The package's module type.  Importing a submodule makes it an attribute
    of the package; for ``render`` and ``sweep``, whose modules define a function
    of the same name, the attribute is the function, as the eager
    ``from .render import render`` used to leave it."""

    def __setattr__(self, name, value):
        if (name in ("render", "sweep") and isinstance(value, _types.ModuleType)
                and value.__name__ == f"{__name__}.{name}"):
            value = getattr(value, name)
        super().__setattr__(name, value)


_sys.modules[__name__].__class__ = _Package
