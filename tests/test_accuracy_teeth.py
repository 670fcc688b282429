"""The image-wide accuracy measurement (lab/accuracy.py) sees a wrong pipeline."""

import pytest

from lab.accuracy import gradient_accuracy


@pytest.mark.parametrize("factor, ulps", [(1.000001, 1e6), (1 + 2.0**-45, 64)])
def test_gradient_accuracy_detects_a_wrong_pipeline(monkeypatch, factor, ulps):
    """A gradient a millionth off, and one 2^-45 off (a few hundred ulps of its scale, just past
    verify/test_accuracy.py's limit of 64): the measurement sees each past its bound."""
    from renderer import pointwise
    original = pointwise.exact_gradient
    monkeypatch.setattr(pointwise, "exact_gradient",
                        lambda *a: tuple(factor * g for g in original(*a)))
    assert gradient_accuracy("sine", count=200)[0].max_ulps > ulps


def test_the_crease_distance_is_the_distance_to_the_nearest_zero_line():
    """Two routes for the ridges field: `crease_distance` (sign changes of its crease factors, located
    numerically) against the closed form min(|u - m/k_u|, |v - m/k_v|) at random points (and each
    term alone, searched along u or v alone); and a reader's
    field with one crease, at u = 2/5, whose distance is |u - 2/5| wherever its other term has none."""
    import numpy as np

    from lab.accuracy import crease_distance
    rng = np.random.default_rng(11)
    u, v = rng.random(500), rng.random(500)
    k_u, k_v = 8.0, 4.0
    closed = np.minimum(np.abs(u * k_u - np.rint(u * k_u)) / k_u, np.abs(v * k_v - np.rint(v * k_v)) / k_v)
    assert np.allclose(crease_distance(u, v, k_u, k_v, "ridges"), closed, rtol=0, atol=1e-15)
    along_u, along_v = (np.abs(x * k - np.rint(x * k)) / k for x, k in ((u, k_u), (v, k_v)))
    assert np.allclose(crease_distance(u, v, k_u, k_v, "ridges", along="u"), along_u, rtol=0, atol=1e-15)
    assert np.allclose(crease_distance(u, v, k_u, k_v, "ridges", along="v"), along_v, rtol=0, atol=1e-15)
    near = np.abs(u - 0.4) < 0.2
    assert np.allclose(crease_distance(u[near], v[near], k_u, k_v, "abs(u - 2/5) + sin(pi*k_v*v)"),
                       np.abs(u[near] - 0.4), rtol=0, atol=1e-15)
    assert np.all(np.isinf(crease_distance(u, v, k_u, k_v, "sine")))
    from renderer import DRAFT_SCENE
    assert np.array_equal(crease_distance(u, v, k_u, k_v), crease_distance(u, v, k_u, k_v, DRAFT_SCENE.height_field))


def test_below_the_bands_width_every_straddling_stencil_lies_in_the_crease_band():
    """§3's claim: while eps is below asin(half-width) / (pi k) in each direction, every sphere-A pixel whose
    stencil reaches across a crease (`crease_distance` below eps) carries the renderer's crease flag; for
    seeded random frequencies.  The check can fail: at five times the width, straddling pixels lie outside."""
    import math

    import numpy as np

    from lab.accuracy import crease_distance
    from renderer import Scene, formulas, gbuffer, render
    from renderer.render import SPHERE_A
    rng = np.random.default_rng(5)
    half = float(formulas.KINK_BAND_HALF_WIDTH)
    for k_u, k_v in [(8.0, 4.0), *rng.integers(2, 13, size=(3, 2)).astype(float)]:
        scene = Scene(height_field="ridges", k_u=k_u, k_v=k_v)
        frame, g = render(scene, 160, 160), gbuffer(scene, 160, 160)
        on_a = g.chamber == SPHERE_A
        dist = crease_distance(g.uv[on_a][:, 0], g.uv[on_a][:, 1], k_u, k_v, "ridges")
        width = math.asin(half) / (math.pi * max(k_u, k_v))
        outside = lambda eps: int(np.sum((dist < eps) & ~frame.kink[on_a]))       # noqa: E731
        assert outside(0.999 * width) == 0, (k_u, k_v)
        assert outside(5 * width) > 0, (k_u, k_v)


def test_each_fields_optimum_stays_below_its_crease_distance(monkeypatch):
    """`optima` takes every registered field from its record, and a field with a crease 0.005 from its
    optimum point measures only steps below that distance (the rule that was the ridges field's alone)."""
    import sympy as sp

    from lab import store
    from lab.accuracy import optima
    from renderer import formulas as F
    crease = sp.Abs(sp.sin(sp.pi * (F.u - sp.Rational(61, 200))))             # at u = 0.305
    creased = F.HeightField("creased", sp.sin(sp.pi * F.k_v * F.v) * crease)
    monkeypatch.setitem(F.FIELDS, "creased", creased)
    monkeypatch.setattr(store, "_MEMORY", {})
    monkeypatch.delenv(store.ENV, raising=False)
    opt = optima()
    assert set(opt) == set(F.FIELDS)
    assert opt["creased"]["crease_distance"] == pytest.approx(0.005, abs=1e-15)
    assert opt["creased"]["largest_step"] < 0.005 < 0.1 == opt["sine"]["largest_step"]
    assert (opt["creased"]["u"], opt["creased"]["v"], opt["creased"]["component"]) == creased.optimum_at


@pytest.mark.parametrize("variant", ["the projection onto N, not N'", "the sign of the projection flipped",
                                     "the renderer's normal without its beta"])
def test_the_normal_derivative_measurement_is_of_the_proved_form_and_the_renderers_normal(monkeypatch, variant):
    """The float64 side is the closed form the theorem normal-beta-derivative proves (its object,
    evaluated through the theorem's names), the reference the renderer's chart-mode normal: a wrong
    closed form planted in the theorem, or a wrong normal in the renderer's record, is measured far
    past verify's 1e-13."""
    import sympy as sp

    from lab import accuracy
    from proofs import normal, registry
    from renderer import formulas as F
    # Built before anything is planted: the catalogue keeps a theorem, and one built from a planted
    # object would be read by every later test of this process (run alone, this test failed so).
    registry.get("normal-beta-derivative")
    with monkeypatch.context() as m:
        if variant == "the renderer's normal without its beta":
            m.setattr(normal, "N_PRIME", normal.N_PRIME.subs(F.beta, 0))
        else:
            projection = normal.N_S if variant.startswith("the projection onto N") else normal.NP_S
            sign = -1 if variant.startswith("the projection") else 1
            m.setattr(normal, "CLAIMED_DERIVATIVE", (sp.Identity(3) + sign * projection * projection.T)
                      * normal.G_S / normal.NORM_M_S)
        accuracy._normal_and_derivative.cache_clear()
        try:
            assert accuracy._normal_beta_derivative_residual(20, 5) > 1e-3
        finally:
            accuracy._normal_and_derivative.cache_clear()
    assert accuracy._normal_beta_derivative_residual(20, 5) < 1e-13


def test_a_candidate_point_is_measured_as_optima_measures_a_registered_one():
    """`measure_optimum` is `optima`'s measurement at any point: at each registered field's point it gives
    what `optima` stores, and it measures a field not registered (a newcomer trying an ``optimum=`` for
    sin(2 pi k_u u) sin(2 pi k_v v) before registering it)."""
    from lab.accuracy import measure_optimum, optima
    for name, o in optima().items():
        assert measure_optimum(name, o["u"], o["v"], o["component"]) == o, name
    tried = measure_optimum("sin(2*pi*k_u*u) * sin(2*pi*k_v*v)", 0.37, 0.47, "u")
    assert (tried["u"], tried["v"], tried["component"]) == (0.37, 0.47, "u")
    assert 1 / 3 < tried["measured_at_fitted"] / tried["error_at_fitted"] < 3


def test_a_point_with_no_optimum_to_measure_is_refused_naming_the_component():
    """Where h''' is 0 but for the reference's last digits (sin(pi k_u u)**2 where the sine is 0: the
    fitted step there fitted noise, 37,900 times the error it claimed), and where it is so small that the
    model's optimum lies past every step: refused, each saying which."""
    import pytest

    from lab.accuracy import measure_optimum
    with pytest.raises(ValueError, match=r"^component must be .* at \(0.25, 0.47\) is 0 \(to the reference's 50 "
                                         r"digits: [\d.e+-]+\), so its central difference has no truncation error"):
        measure_optimum("sin(pi*k_u*u)**2 * sin(pi*k_v*v)**2", 0.25, 0.47, "u")
    with pytest.raises(ValueError, match=r"^component must be .* is 6e-15, so small that its model-optimal step "
                                         r"\(1\.\d+\) lies past every step tried \(the largest 0\.1\)"):
        measure_optimum("1e-15*u**3 + 100", 0.3, 0.4, "u")
    near = measure_optimum("sin(pi*k_u*u)**2 * sin(pi*k_v*v)**2", 0.15, 0.47, "u")     # away from it: measured
    assert 1 / 3 < near["measured_at_fitted"] / near["error_at_fitted"] < 3


def test_an_optimum_keeps_the_steps_its_own_stencil_allows():
    """A U-curve of h_u moves only in u: a v-crease 0.02 away limits none of its steps, the u-crease
    0.06 away does; on a u-crease no two steps are left, and that is said in one line."""
    import pytest

    from lab.accuracy import measure_optimum
    o = measure_optimum("ridges", 0.31, 0.52, "u")
    assert o["crease_distance"] == pytest.approx(0.06) and 0.02 < o["largest_step"] < 0.06
    with pytest.raises(RuntimeError, match=r"^the ridges field's point \(0.25, 0.4\) is [\d.e+-]+ from a crease: "
                                           r"fewer than two of the default steps lie below that$"):
        measure_optimum("ridges", 0.25, 0.4, "u")


def test_the_frame_model_step_is_the_model_at_the_charts_largest_c_and_third_derivative():
    """`frame_model_step` against a second route: for sin(pi k_u u) sin(pi k_v v) at random frequencies the
    largest |h'''| along u is (pi k_u)^3, and the largest C = |h| + |u h_u| is the largest, over u alone on
    a fine grid, of |sin(pi k_u u)| + pi k_u u |cos(pi k_u u)| (where |sin(pi k_v v)| = 1); likewise along v.
    The ridges field, |.| of the same product, has the same steps (its deltas on the creases dropped); a direction along which h is constant has
    none; and a step a tenth off would be seen (the grid's sampling error is far smaller)."""
    import numpy as np

    from lab.accuracy import frame_model_step
    from renderer.ucurve import UNIT_ROUNDOFF
    x = np.linspace(0.0, 1.0, 400_001)
    for k_u, k_v in np.random.default_rng(12).uniform(1.0, 12.0, (4, 2)):
        want = {}
        for name, k in (("u", k_u), ("v", k_v)):
            c = np.max(np.abs(np.sin(np.pi * k * x)) + np.pi * k * x * np.abs(np.cos(np.pi * k * x)))
            want[name] = (3 * UNIT_ROUNDOFF * c / (np.pi * k) ** 3) ** (1 / 3)
        got = frame_model_step("sine", k_u=k_u, k_v=k_v)
        assert all(abs(got[d] / want[d] - 1) < 1e-3 for d in "uv"), (k_u, k_v, got, want)
        ridges = frame_model_step("ridges", k_u=k_u, k_v=k_v)        # sign(0) = 0 on a crease's grid points
        assert all(abs(ridges[d] / got[d] - 1) < 1e-3 for d in "uv"), (ridges, got)
    assert frame_model_step("rings")["u"] is None and frame_model_step("rings")["v"] > 0
