"""The samplers behind the theorems' evidence and the claims' measurements pick what their
docstrings say they pick: the pixel sampler's crease neighbours lie next to a crease and its pole
frames about the pole (proofs/pixels.py), the stencil's border points at the borders
(proofs/finite_difference.py), and the claims measured at a step are measured at that step
(lab/claims.py).  A sampler that drifts away (the complement, a random pick, another zoom) leaves
every comparison it feeds passing on easier points: these tests measure the points themselves.
"""

import numpy as np
import pytest

from proofs.frame import SEED_POLE_SIN_PHI
from proofs.pixels import CREASE_BAND, PER_FIELD, SOURCES, pixels
from renderer import formulas as F


def _chart_distance_to_crease(uv, k_u, k_v):
    """Distance of each chart point to the nearest zero line of the ridges field, u = m / k_u or
    v = m / k_v, in units of the line's period (1 / k_u or 1 / k_v): over the lines themselves."""
    lines_u, lines_v = np.arange(np.ceil(k_u) + 1) / k_u, np.arange(np.ceil(k_v) + 1) / k_v
    d_u = np.abs(uv[:, :1] - lines_u[None]).min(axis=1) * k_u
    d_v = np.abs(uv[:, 1:] - lines_v[None]).min(axis=1) * k_v
    return np.minimum(d_u, d_v)


def test_crease_neighbours_lie_within_the_stated_band_of_a_crease():
    scene, px = pixels("ridges")
    crease = px["source"] == "crease"
    assert np.count_nonzero(crease) == PER_FIELD // 3
    d = _chart_distance_to_crease(px["uv"][crease], scene.k_u, scene.k_v)
    assert d.max() < CREASE_BAND, d.max()
    # The measure tells them apart: the full frame's random pixels are mostly farther than the band.
    anywhere = _chart_distance_to_crease(px["uv"][px["source"] == "frame"], scene.k_u, scene.k_v)
    assert np.mean(anywhere < CREASE_BAND) < 0.5
    assert CREASE_BAND <= 0.1                          # next to a crease: within a tenth of a period of it


@pytest.mark.parametrize("field", list(F.FIELDS))
def test_each_source_lies_where_documented_the_pole_frames_about_the_pole(field):
    """sin(phi) = |(N_x, N_y)| of each source's pixels within its `SOURCES` bounds; the zoom-3e4 frame all
    inside the draft's fallback radius sin(phi) = 1e-4 (where the renderer keeps the chart's frame), and
    PER_FIELD's 200 pixels outside it."""
    _, px = pixels(field)
    sin_phi = np.hypot(px["N"][:, 0], px["N"][:, 1])
    for name, _, lo, hi in SOURCES:
        rows = sin_phi[px["source"] == name]
        assert rows.size == PER_FIELD // 3, name
        assert lo <= rows.min() and rows.max() <= hi, (name, rows.min(), rows.max())
    assert np.all(sin_phi[px["source"] == "pole-3e4"] <= SEED_POLE_SIN_PHI)
    assert np.count_nonzero(sin_phi > SEED_POLE_SIN_PHI) >= 200
    assert set(px["source"]) == {name for name, *_ in SOURCES} | ({"crease"} if field == "ridges" else set())


def test_the_border_points_take_every_wrap_and_clamp_often():
    """Each of the four border rules (u wraps above 1, below 0; v clamps above 1, below 0) at no fewer than a
    fifth of the points, and the interior branch at no more than half: a uniform draw would reach the
    borders at about one point in a hundred."""
    from proofs.finite_difference import border_points
    u, v, step = np.array(list(border_points())).T
    assert u.size == 2000
    taken = {"u wraps above": u + step >= 1, "u wraps below": u - step < 0,
             "v clamps above": v + step > 1, "v clamps below": v - step < 0}
    for rule, where in taken.items():
        assert np.mean(where) >= 0.2, (rule, np.mean(where))
    assert np.mean(~np.any(list(taken.values()), axis=0)) <= 0.5


def test_a_claim_at_a_step_is_measured_at_that_step(monkeypatch):
    """The claims about 1e-9 and 1e-11 read the U-curve at those steps: on a curve without them the
    measurement is refused, naming the step, rather than read at the nearest (1e-6 here)."""
    from types import SimpleNamespace

    from lab import claims
    curve = SimpleNamespace(eps=np.array([1e-3, 1e-6, 1.005e-9]), error=np.array([1e-7, 1e-11, 1e-9]),
                            derivative=-2.0)
    monkeypatch.setattr(claims, "_ucurve", lambda: curve)
    assert claims.relative_error_at(1e-9) == 0.5e-9                # within 1 %: that step
    with pytest.raises(ValueError, match=r"^eps=1e-11: the U-curve's nearest step is 1e-09; a claim at a step "
                                         r"is measured within 1 % of it$"):
        claims.relative_error_at(1e-11)
    with pytest.raises(ValueError, match="eps=9e-07"):
        claims.relative_error_at(9e-7)


def test_the_stacking_claim_compares_only_blocks_whose_samples_are_all_on_sphere_a(monkeypatch):
    """Claim stacking measures the 4 x 4 box filter against one sample per pixel, and against a 2 x 2 box,
    where all 16 samples of the pixel lie on sphere A: a block with a sample off A averages another object in.
    Planted frames: the one sample misses the box by 0.02 with the bump and 0.01 without it on every block, the
    2 x 2 box by 0.01 and 0.007, and every block of the first row has one sample off A (0 there), which would
    add its 1/32 to the miss were it compared."""
    from types import SimpleNamespace

    from lab import claims

    def render(scene, width, height, **_):
        chamber = np.ones((height, width), np.uint8)
        image = np.full((height, width, 3), 0.5)
        if width == 512:
            chamber[0, ::4] = 0
            image[0, ::4] = 0.0
        elif width == 256:                   # a checkerboard of +-0.03 inside each 2 x 2 block: averaged away
            image += 0.01 if scene.beta else 0.007
            image[::2, ::2] += 0.03
            image[1::2, 1::2] -= 0.03
        else:
            image += 0.02 if scene.beta else 0.01
        return SimpleNamespace(image=image, chamber=chamber, scene=scene)
    monkeypatch.setattr(claims, "render", render)
    values = claims._stacking()
    assert values["one-sample error, with / without the bump"] == pytest.approx(2.0, rel=1e-12, abs=0)
    assert (values[claims.CONVERGES], values["flat_2x2"]) == (pytest.approx(0.5, rel=1e-12, abs=0),
                                                              pytest.approx(0.7, rel=1e-12, abs=0))
    assert (values["bumped"], values["flat"]) == (pytest.approx(0.02, rel=1e-12, abs=0), pytest.approx(0.01, rel=1e-12, abs=0))
