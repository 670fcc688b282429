"""The kernel reads its inputs by name, so a changed layout cannot shift them.

`renderer.kernel.params` fills each field of the `SCENE` record from the
Scene attribute of its name (or `DERIVED`), and the lights into `LIGHT`
records.  Checked here:

* every field holds its own quantity, on a scene whose quantities all differ;
* the fields in another order, with one inserted before them, change no bit
  of the image (positions do not matter);
* a misnamed field is refused by `params`, naming it, and a field the kernel
  reads that the record lacks stops the compilation: neither renders.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest
from numba.core.caching import NullCache

from renderer import PointLight, Scene, kernel, render

SCENE = Scene(camera_z=4.5, radius_a=1.1, center_b=(1.3, -0.4, 0.2), radius_b=0.35, sphere_b=True, floor=True,
              ambient=(0.11, 0.12, 0.13), albedo_a=(0.61, 0.62, 0.63), albedo_b=(0.71, 0.72, 0.73), ka=0.21,
              kd=0.66, ks=0.31, shininess=17.0, model="phong", floor_tint=0.07, height_field="rings", k_u=9.0,
              k_v=5.0, beta=0.45, bump="chart",
              lights=(PointLight((2.0, 3.0, 6.0), (0.9, 0.8, 0.7)), PointLight((-4.0, 1.0, 5.0), (0.0, 0.0, 0.0)),
                      PointLight((1.0, -2.0, 7.0), (0.3, 0.4, 0.5))))
EXPECTED = dict(camera_z=4.5, radius_a=1.1, center_b=(1.3, -0.4, 0.2), radius_b=0.35, sphere_b=True, floor=True,
                ambient=(0.11, 0.12, 0.13), albedo_a=(0.61, 0.62, 0.63), albedo_b=(0.71, 0.72, 0.73), ka=0.21,
                kd=0.66, ks=0.31, shininess=17.0, phong=True, floor_tint=0.07, k_u=9.0, k_v=5.0,
                beta=0.45, surface=False)


def test_each_field_holds_its_own_quantity():
    prm, lights = kernel.params(SCENE)
    assert prm.shape == (1,) and set(kernel.SCENE.names) == set(EXPECTED)
    assert {name: np.asarray(prm[0][name]).tolist() for name in kernel.SCENE.names} == \
        {name: list(v) if isinstance(v, tuple) else v for name, v in EXPECTED.items()}
    assert lights.position.tolist() == [[2.0, 3.0, 6.0], [1.0, -2.0, 7.0]]      # the dark light left out
    assert lights.color.tolist() == [[0.9, 0.8, 0.7], [0.3, 0.4, 0.5]]
    assert kernel.params(SCENE, skip=False)[1].position[:, 0].tolist() == [2.0, -4.0, 1.0]


@pytest.fixture
def reference():
    return render(SCENE, 12, 10, gradient="footprint")


@pytest.fixture
def uncached(monkeypatch):
    """The kernel's functions compiled in memory only while a test changes the record: its
    specializations stay out of numba's cache on disk, which two processes writing at once
    can leave naming one layout's code under another's signature."""
    for obj in vars(kernel).values():
        if isinstance(obj, numba.core.registry.CPUDispatcher):
            monkeypatch.setattr(obj, "_cache", NullCache())


def _layout(names, extra=()):
    """`kernel.SCENE` with its fields in the order of ``names``, ``extra`` (name, dtype) pairs first."""
    return np.dtype([*extra, *((n, kernel.SCENE.fields[n][0]) for n in names)], align=True)


def test_the_layout_changes_no_bit(monkeypatch, reference, uncached):
    """The fields reversed and one inserted before them (one compilation: each costs a minute)."""
    names = kernel.SCENE.names
    changed = _layout(names[::-1], [("unused", "f8")])
    assert [changed.fields[n][1] for n in names] != [kernel.SCENE.fields[n][1] for n in names]    # offsets moved
    monkeypatch.setattr(kernel, "SCENE", changed)
    monkeypatch.setattr(kernel, "DERIVED", dict(kernel.DERIVED, unused=lambda scene: 123.0))
    frame = render(SCENE, 12, 10, gradient="footprint")
    for name in ("image", "grad", "kink", "chamber"):
        assert getattr(frame, name).tobytes() == getattr(reference, name).tobytes(), name


def test_a_misnamed_field_is_refused_by_name(monkeypatch):
    names = kernel.SCENE.names
    monkeypatch.setattr(kernel, "SCENE", np.dtype([("radius_B" if n == "radius_b" else n, kernel.SCENE.fields[n][0])
                                                   for n in names], align=True))
    with pytest.raises(AttributeError, match="'radius_B'"):
        render(SCENE, 4, 4)


def test_a_field_the_kernel_reads_and_the_record_lacks_stops_the_compilation(monkeypatch, uncached):
    monkeypatch.setattr(kernel, "SCENE", _layout([n for n in kernel.SCENE.names if n != "beta"]))
    with pytest.raises((numba.core.errors.TypingError, KeyError), match="beta"):
        render(SCENE, 4, 4)
