"""The lab's image measurements against independent routes, at random scenes.

A measurement helper compared only with itself, at the defaults, hides a slip that swaps the two
chart directions, a field's two frequencies or the two spheres: at k_u = 8, k_v = 4 a census that
reads k_u twice still finds creases.  Here each helper runs on seeded random scenes whose
frequencies, amplitude, camera and second sphere all differ from the defaults and from each other,
and is held against a route of its own:

* which stencils straddle a crease (`lab.claims._census`'s ``straddling``, `lab.accuracy._crease_share`):
  against the crossings of an integer by k_u (u -+ eps) or k_v (v -+ eps), the ridges field's zero lines
  counted with integers, not located by root finding;
* the census's ledger (RMS, largest difference, means on and off the crease band): against the same
  sums taken by numpy over the two frames' pixels, not by `renderer.compare`.
"""

import numpy as np
import pytest

from lab.accuracy import _crease_share
from lab.claims import CENSUS_STEPS, _census
from renderer import DRAFT_SCENE, gbuffer, render
from renderer.render import SPHERE_A

SIZE = 40


def _scenes(count=3, seed=2026):
    """Random ridges scenes: k_u and k_v at least 1.5 apart, and beta, the camera and sphere B moved."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        k_u, k_v = rng.uniform(2.0, 12.0, 2)
        if abs(k_u - k_v) < 1.5:
            continue
        out.append(DRAFT_SCENE.replace(k_u=float(k_u), k_v=float(k_v), beta=float(rng.uniform(0.1, 0.6)),
                                       camera_z=float(rng.uniform(3.5, 6.0)), radius_b=float(rng.uniform(0.2, 0.4)),
                                       center_b=tuple(float(x) for x in rng.uniform([0.3, 0.3, 1.1], [0.7, 0.7, 1.5]))))
    return out


def _straddles(scene, size, eps):
    """Sphere-A pixels whose stencil u -+ eps or v -+ eps crosses a zero line m/k_u or m/k_v, counted
    by the integer parts of k (u -+ eps) and k (v -+ eps)."""
    g = gbuffer(scene, size, size)
    u, v = g.uv[g.chamber == SPHERE_A].T
    crosses = lambda x, k: np.floor(k * (x - eps)) != np.floor(k * (x + eps))   # noqa: E731
    return crosses(u, scene.k_u) | crosses(v, scene.k_v)


@pytest.mark.parametrize("scene", _scenes(), ids=lambda s: f"ku{s.k_u:.2f}-kv{s.k_v:.2f}")
def test_the_crease_share_counts_the_stencils_that_cross_a_zero_line(scene):
    steps = [3e-2, 1e-2, 3e-3]
    share = _crease_share(SIZE, steps, scene)
    assert share["share"] == [pytest.approx(float(np.mean(_straddles(scene, SIZE, e))), abs=1e-12) for e in steps]
    assert share["pixels"] == _straddles(scene, SIZE, 1e-3).size


@pytest.mark.parametrize("scene", _scenes(2, seed=7), ids=lambda s: f"ku{s.k_u:.2f}-kv{s.k_v:.2f}")
def test_the_census_is_its_frames_sums_and_its_straddling_count(scene):
    c = _census(SIZE, scene)
    symbolic = render(scene, SIZE, SIZE)
    on_a = symbolic.chamber == SPHERE_A
    for k, eps in enumerate(CENSUS_STEPS):
        numeric = render(scene.replace(eps=eps), SIZE, SIZE, gradient="central")
        both = on_a & (numeric.chamber == SPHERE_A)
        d = np.abs(numeric.image - symbolic.image)[both]                  # (pixels, 3)
        band = symbolic.kink[both]
        assert c["rms"][k] == pytest.approx(float(np.sqrt(np.mean(d**2))), rel=1e-12)
        assert c["max"][k] == float(d.max())
        if band.any():
            assert c["on_band"][k] == pytest.approx(float(d[band].mean()), rel=1e-12)
        assert c["off_band"][k] == pytest.approx(float(d[~band].mean()), rel=1e-12)
        assert c["flips"][k] == int(np.count_nonzero(numeric.chamber != symbolic.chamber))
        assert c["straddling"][k] == int(np.count_nonzero(_straddles(scene, SIZE, eps)))


def test_a_census_that_reads_one_frequency_twice_is_caught(monkeypatch):
    """The wrong variant: the census's crease distance taking k_u for both directions."""
    import lab.accuracy as accuracy
    real = accuracy.crease_distance
    monkeypatch.setattr(accuracy, "crease_distance", lambda u, v, k_u, k_v, field=None: real(u, v, k_u, k_u, field))
    scene = _scenes(1, seed=7)[0]
    c = _census(SIZE, scene)
    assert c["straddling"] != [int(np.count_nonzero(_straddles(scene, SIZE, e))) for e in CENSUS_STEPS]
