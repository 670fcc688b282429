"""The vectorized renderer against the independent scalar reference.

Every height field x both models x both pipelines x sphere B on/off x floor
on/off x beta in {0, 0.35, 1.5}, on small odd and non-square frames: the same
chamber codes and crease flags, |dI| <= 1e-12 per channel.
"""

import itertools

import numpy as np
import pytest

from renderer import Scene, render
from tests import reference_renderer as ref

W, H = 41, 34          # odd width: a column of pixel centres lies on x = 0

CASES = list(itertools.product(("sine", "ridges", "rings"), ("blinn", "phong"),
                               ("exact", "central"), (True, False), (True, False),
                               (0.0, 0.35, 1.5)))


def compare_with_reference(scene, gradient, width=W, height=H):
    """Return (chamber mismatches, kink mismatches, max |dI|, max |d grad| / (1 + |grad|))."""
    frame = render(scene, width, height, gradient=gradient)
    image, chamber, kink, grad = (np.asarray(a) for a in
                                  ref.render_reference(scene, width, height, gradient=gradient))
    return (int(np.count_nonzero(frame.chamber != chamber)),
            int(np.count_nonzero(frame.kink != kink)),
            float(np.abs(frame.image - image).max()),
            float((np.abs(frame.grad - grad) / (1 + np.abs(grad))).max()))


@pytest.mark.parametrize("field, model, gradient, sphere_b, floor, beta", CASES)
def test_matches_scalar_reference(field, model, gradient, sphere_b, floor, beta):
    scene = Scene(height_field=field, model=model, sphere_b=sphere_b, floor=floor, beta=beta)
    chamber, kink, d_image, d_grad = compare_with_reference(scene, gradient)
    assert chamber == 0
    assert kink == 0
    assert d_image <= 1e-12
    # The gradient itself: exact closed forms agree to rounding; the central
    # quotient divides a difference of two h values (each within an ulp of the
    # libm value) by 2 eps = 2e-3, so 1e-12 relative still holds with margin.
    assert d_grad <= 1e-12


@pytest.mark.parametrize("field", ["sine", "ridges", "rings"])
@pytest.mark.parametrize("gradient", ["exact", "central"])
@pytest.mark.parametrize("beta", [0.35, 0.9])
def test_surface_bump_matches_scalar_reference(field, gradient, beta):
    scene = Scene(height_field=field, bump="surface", beta=beta)
    chamber, kink, d_image, d_grad = compare_with_reference(scene, gradient)
    assert (chamber, kink) == (0, 0)
    assert d_image <= 1e-12 and d_grad <= 1e-12


def test_reference_parity_has_teeth(monkeypatch):
    """The comparison rejects wrong variants of the scene and of the reference."""
    scene = Scene(beta=0.35)
    # A scene that differs in one field is caught...
    frame = render(scene.replace(k_u=8.5), W, H)
    image = np.asarray(ref.render_reference(scene, W, H)[0])
    assert np.abs(frame.image - image).max() > 1e-3
    # ...and so is the seed's sphere-B quadratic (constant term |C|^2 - r^2).
    original = ref.ray_sphere

    def seed_ray_sphere(x, y, e, C, r):
        if C == scene.center_b:
            a = x * x + y * y + e * e
            b = -C[0] * x - C[1] * y - (e - C[2]) * e
            disc = b * b - a * (C[0] ** 2 + C[1] ** 2 + C[2] ** 2 - r * r)
            return (-b - disc ** 0.5) / a if disc >= 0 else None
        return original(x, y, e, C, r)

    monkeypatch.setattr(ref, "ray_sphere", seed_ray_sphere)
    chamber, _, d_image, _ = compare_with_reference(scene, "exact")
    assert chamber > 0 and d_image > 0.1


def test_terminator_rule_is_what_parity_checks(monkeypatch):
    """Dropping the geometric attached-shadow test (the seed's rule) breaks parity."""
    calls = {"n": 0}

    # Replace shade's geometric test by the seed's: light counts wherever N'.w > 0.
    def seed_shade(scene, P, N, Ns, albedo, blockers, floor_blocks):
        calls["n"] += 1
        return original_shade(scene, P, Ns, Ns, albedo, blockers, floor_blocks)

    original_shade = ref.shade
    monkeypatch.setattr(ref, "shade", seed_shade)
    scene = Scene(beta=1.5)
    _, _, d_image, _ = compare_with_reference(scene, "exact", 40, 32)
    assert calls["n"] > 0
    assert d_image > 1e-2
