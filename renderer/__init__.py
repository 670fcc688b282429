"""Renderer of the Chapter-9 scene (two spheres, two point lights, a checker
floor, bump-mapped sphere A) with a numeric (central difference) and a
symbolic (exact gradient) pipeline: one per-pixel kernel compiled with numba
(`renderer.kernel`), its formulas generated from the sympy objects of
`renderer.formulas`.

Public API::

    from renderer import Scene, render
    frame = render(Scene(), 256, 256, gradient="exact")
"""

import importlib
import sys
import types

#: Each public name and the submodule that defines it, loaded on first use (PEP 562):
#: ``import renderer`` alone loads neither numpy nor the compiled kernel, so the command
#: line starts at once and ``python -m renderer.codegen`` runs even when the kernel's
#: digest guard would refuse the generated file it is about to rewrite.
_WHERE = {
    "Scene": "scene", "PointLight": "scene", "BUMPS": "scene", "HEIGHT_FIELDS": "scene",
    "MODELS": "scene", "frame_label": "scene",
    "render": "render", "gbuffer": "render", "Frame": "render", "GBuffer": "render",
    "GRADIENTS": "render", "CHAMBER_NAMES": "render",
    "Ledger": "ledger", "compare": "ledger", "to_srgb": "ledger",
    "Sweep": "sweep", "sweep": "sweep",
}
__all__ = list(_WHERE)


def __getattr__(name):
    if name not in _WHERE:
        raise AttributeError(f"module 'renderer' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_WHERE[name]}"), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_WHERE))


class _Package(types.ModuleType):
    """``render`` and ``sweep`` name both a function of the API and the submodule that
    defines it; the import system binds a loaded submodule to its package's attribute,
    which would hide the function, so the package keeps the function (the submodules
    stay in ``sys.modules``)."""

    def __setattr__(self, name, value):
        if name in ("render", "sweep") and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
