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
  sums taken by numpy over the two frames' pixels, not by `renderer.compare`;
* `lab.accuracy.gradient_accuracy` (every field): its pixels against sphere A's in the G-buffer, its errors
  against mpmath differentiating h itself (``mpmath.diff``, not the sympy gradient the renderer compiles)
  and a central quotient written here (u wrapped, v clamped);
* the image-best step (`lab.accuracy._image_best_step`, every field): against the least RMS |dI| of
  frames rendered one step at a time (`renderer.render`, not the sweep);
* the central difference's optima (`lab.accuracy._optima`) at random points, directions and
  frequencies: the crease distance against integers, h, h' and h''' against mpmath, the model-optimal
  step against its formula.
"""

import mpmath
import numpy as np
import pytest
import sympy as sp

import lab.accuracy as accuracy
from lab.accuracy import _crease_share, _image_best_step, _optima, gradient_accuracy
from lab.claims import CENSUS_STEPS, _census
from renderer import DRAFT_SCENE, Scene, gbuffer, pointwise, render
from renderer import formulas as F
from renderer.render import SPHERE_A
from renderer.ucurve import DEFAULT_STEPS, UNIT_ROUNDOFF

SIZE = 40


def _scenes(count=3, seed=2026, field="ridges"):
    """Random scenes of ``field``: k_u and k_v at least 1.5 apart, and beta, the camera and sphere B moved."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        k_u, k_v = rng.uniform(2.0, 12.0, 2)
        if abs(k_u - k_v) < 1.5:
            continue
        out.append(DRAFT_SCENE.replace(height_field=field, k_u=float(k_u), k_v=float(k_v), beta=float(rng.uniform(0.1, 0.6)),
                                       camera_z=float(rng.uniform(3.5, 6.0)), radius_b=float(rng.uniform(0.2, 0.4)),
                                       center_b=tuple(float(x) for x in rng.uniform([0.3, 0.3, 1.1], [0.7, 0.7, 1.5]))))
    return out


def _straddles(scene, size, eps, along_v=True):
    """Sphere-A pixels whose stencil u -+ eps or v -+ eps crosses a zero line m/k_u or m/k_v, counted
    by the integer parts of k (u -+ eps) and k (v -+ eps); with ``along_v`` False, the lines m/k_u only."""
    g = gbuffer(scene, size, size)
    u, v = g.uv[g.chamber == SPHERE_A].T
    crosses = lambda x, k: np.floor(k * (x - eps)) != np.floor(k * (x + eps))   # noqa: E731
    return crosses(u, scene.k_u) | (crosses(v, scene.k_v) & along_v)


@pytest.mark.parametrize("scene", _scenes(), ids=lambda s: f"ku{s.k_u:.2f}-kv{s.k_v:.2f}")
def test_the_crease_share_counts_the_stencils_that_cross_a_zero_line(scene):
    steps = [3e-2, 1e-2, 3e-3]
    share = _crease_share(SIZE, steps, scene)
    assert share["share"] == [pytest.approx(float(np.mean(_straddles(scene, SIZE, e))), abs=1e-12) for e in steps]
    assert share["pixels"] == _straddles(scene, SIZE, 1e-3).size
    assert share["share_u"] == [pytest.approx(float(np.mean(_straddles(scene, SIZE, e, along_v=False))), abs=1e-12)
                                for e in steps]


@pytest.mark.parametrize("scene", _scenes(2, seed=7) + _scenes(1, seed=8, field="sine"),
                         ids=lambda s: f"{s.height_field}-ku{s.k_u:.2f}-kv{s.k_v:.2f}")
def test_the_census_is_its_frames_sums_and_its_straddling_count(scene):
    """The census against numpy's sums over its frames; its straddling count against the zero lines
    crossed, which are creases of ridges and of no line of sine (a field without creases straddles none)."""
    creased = bool(F.FIELDS[scene.height_field].crease_factors)
    c = _census(SIZE, scene)
    symbolic = render(scene, SIZE, SIZE)
    on_a = symbolic.chamber == SPHERE_A
    for k, eps in enumerate(CENSUS_STEPS):
        numeric = render(scene.replace(eps=eps), SIZE, SIZE, gradient="central")
        both = on_a & (numeric.chamber == SPHERE_A)
        d = np.abs(numeric.image - symbolic.image)[both]                  # (pixels, 3)
        band = symbolic.kink[both]
        assert c["rms"][k] == pytest.approx(float(np.sqrt(np.mean(d**2))), rel=1e-12, abs=0)
        assert c["max"][k] == float(d.max())
        if band.any():
            assert c["on_band"][k] == pytest.approx(float(d[band].mean()), rel=1e-12, abs=0)
        assert c["off_band"][k] == pytest.approx(float(d[~band].mean()), rel=1e-12, abs=0)
        assert c["flips"][k] == int(np.count_nonzero(numeric.chamber != symbolic.chamber))
        assert c["straddling"][k] == (int(np.count_nonzero(_straddles(scene, SIZE, eps))) if creased else 0)


def test_a_census_that_reads_one_frequency_twice_is_caught(monkeypatch):
    """The wrong variant: the census's crease distance taking k_u for both directions."""
    import lab.accuracy as accuracy
    real = accuracy.crease_distance
    monkeypatch.setattr(accuracy, "crease_distance", lambda u, v, k_u, k_v, field=None: real(u, v, k_u, k_u, field))
    scene = _scenes(1, seed=7)[0]
    c = _census(SIZE, scene)
    assert c["straddling"] != [int(np.count_nonzero(_straddles(scene, SIZE, e))) for e in CENSUS_STEPS]


def _h(field, k_u, k_v, modules):
    """h(u, v) of ``field`` at these frequencies, lambdified for ``modules``."""
    expr = F.FIELDS[field].expr.subs({F.k_u: sp.nsimplify(k_u), F.k_v: sp.nsimplify(k_v)})
    return sp.lambdify((F.u, F.v), expr, modules=modules)


def _partial(h, u, v, component, order=1):
    """The order-th partial derivative of h along ``component`` at (u, v), by mpmath.diff, 30 digits."""
    with mpmath.workdps(30):
        u, v = mpmath.mpf(float(u)), mpmath.mpf(float(v))
        if component == "u":
            return mpmath.diff(lambda x: h(x, v), u, order)
        return mpmath.diff(lambda y: h(u, y), v, order)


def _accuracy_route(field, k_u, k_v, steps, monkeypatch):
    """(gradient_accuracy's records, the same records computed here), SIZE squared, 40 pixels."""
    seen = []
    real = pointwise.exact_gradient
    monkeypatch.setattr(pointwise, "exact_gradient",
                        lambda f, u, v, ku, kv: seen.append((u.copy(), v.copy())) or real(f, u, v, ku, kv))
    got = gradient_accuracy(field, count=40, size=SIZE, seed=3, steps=steps, k_u=k_u, k_v=k_v)
    (u, v), = seen
    g = gbuffer(Scene(height_field=field, k_u=k_u, k_v=k_v), SIZE, SIZE)
    pixels = {(float(a), float(b)) for a, b in g.uv[g.chamber == SPHERE_A]}
    assert len(u) >= 30 and all((float(a), float(b)) in pixels for a, b in zip(u, v))
    assert len(set(zip(u.tolist(), v.tolist()))) == len(u)
    h_mp, h = _h(field, k_u, k_v, "mpmath"), _h(field, k_u, k_v, "numpy")
    ref = [[_partial(h_mp, a, b, c) for c in "uv"] for a, b in zip(u, v)]
    pairs = [real(F.FIELDS[field], u, v, k_u, k_v)]
    for eps in steps:
        lo, hi = np.maximum(v - eps, 0.0), np.minimum(v + eps, 1.0)
        pairs.append(((h((u + eps) % 1.0, v) - h((u - eps) % 1.0, v)) / (2 * eps), (h(u, hi) - h(u, lo)) / (hi - lo)))
    scale = np.spacing(F.gradient_scale(k_u, k_v))
    mine = []
    for hu, hv in pairs:
        with mpmath.workdps(30):          # the exact gradient's errors are ulps: subtract at 30 digits
            err = np.array([[float(abs(mpmath.mpf(float(x)) - r)) for x, r in zip(pair, refs)]
                            for pair, refs in zip(zip(hu, hv), ref)])
        mine.append((len(u), float(err.max()), float(np.sqrt(np.mean(err**2))), float(err.max() / scale)))
    return [(r.pixels, r.max_abs, r.rms_abs, r.max_ulps) for r in got], mine


@pytest.mark.parametrize("field", sorted(F.FIELDS))
def test_gradient_accuracy_is_mpmath_differentiating_h_at_sphere_a_pixels(field, monkeypatch):
    """Random frequencies k_u != k_v; steps large enough that truncation, not rounding, sets the
    central errors (so a quotient evaluated another way agrees to many digits)."""
    scene = _scenes(1, seed=11, field=field)[0]
    got, mine = _accuracy_route(field, scene.k_u, scene.k_v, [3e-2, 3e-3], monkeypatch)
    assert len(got) == len(mine) == 3                  # the exact gradient and the two steps
    for g, m in zip(got, mine):
        assert g == pytest.approx(m, rel=1e-6, abs=0)


def test_a_reference_with_its_frequencies_swapped_is_caught(monkeypatch):
    """The wrong variant: gradient_accuracy's mpmath reference built with k_u and k_v exchanged."""
    real = accuracy._reference.__wrapped__
    monkeypatch.setattr(accuracy, "_reference", lambda field, ku, kv: real(field, kv, ku))
    scene = _scenes(1, seed=11, field="sine")[0]
    got, mine = _accuracy_route("sine", scene.k_u, scene.k_v, [3e-3], monkeypatch)
    assert got[0] != pytest.approx(mine[0], rel=1e-6, abs=0)


def _frame_rms(scene, steps):
    """RMS |ΔI| over the pixels both frames see on sphere A, each step's central frame rendered alone
    against the exact frame."""
    exact = render(scene, SIZE, SIZE)
    rms = []
    for eps in steps:
        central = render(scene.replace(eps=eps), SIZE, SIZE, gradient="central")
        both = (exact.chamber == SPHERE_A) & (central.chamber == SPHERE_A)
        rms.append(float(np.sqrt(np.mean((central.image - exact.image)[both] ** 2))))
    return rms


BEST_STEPS = [1e-1, 3e-2, 1e-2, 1e-3, 1e-5, 1e-7]


@pytest.mark.parametrize("field", sorted(F.FIELDS))
def test_the_image_best_step_is_the_least_rms_of_frames_rendered_one_by_one(field, monkeypatch):
    """On a random scene of the field (either bump mode) put in the simulator scene's place."""
    import renderer.ledger as ledger
    scene = _scenes(1, seed=23, field=field)[0].replace(bump=("surface", "chart")[len(field) % 2])
    monkeypatch.setattr(ledger, "SIMULATOR_SCENE", scene)
    got = _image_best_step(field, SIZE, BEST_STEPS)
    rms = _frame_rms(scene, BEST_STEPS)
    assert got["rms"] == pytest.approx(rms, rel=1e-9, abs=0)
    assert got["best"] == BEST_STEPS[int(np.argmin(rms))]
    assert got["steps"] == BEST_STEPS and got["size"] == [SIZE, SIZE] and got["scene"] == scene.changes()


def test_an_image_best_step_with_its_frequencies_swapped_is_caught(monkeypatch):
    """The wrong variant: the measurement run on the scene with k_u and k_v exchanged."""
    import renderer.ledger as ledger
    scene = _scenes(1, seed=23, field="ridges")[0]
    monkeypatch.setattr(ledger, "SIMULATOR_SCENE", scene.replace(k_u=scene.k_v, k_v=scene.k_u))
    assert _image_best_step("ridges", SIZE, BEST_STEPS)["rms"] != pytest.approx(_frame_rms(scene, BEST_STEPS), rel=1e-9, abs=0)


def _optima_route(seed, monkeypatch):
    """(`_optima` at random frequencies and a random point and direction per field, what it should say)."""
    rng = np.random.default_rng(seed)
    k_u, k_v = _scenes(1, seed=seed)[0].k_u, _scenes(1, seed=seed)[0].k_v
    monkeypatch.setattr(accuracy, "DRAFT_SCENE", DRAFT_SCENE.replace(k_u=k_u, k_v=k_v))
    points = {}
    for name in F.FIELDS:
        component = str(rng.choice([c for c, s in (("u", F.u), ("v", F.v))      # one h varies along
                                     if s in F.FIELDS[name].expr.free_symbols]))
        while True:              # the nearest crease along the component's coordinate, where the stencil moves
            u, v = (float(x) for x in rng.uniform(0.05, 0.95, 2))
            x, k = (u, k_u) if component == "u" else (v, k_v)
            distance = abs(x * k - round(x * k)) / k if F.FIELDS[name].crease_factors else np.inf
            if distance > 1e-3:
                break
        points[name] = (u, v, component, distance if distance <= accuracy.CREASE_REACH else np.inf)
    got = _optima({name: [str(F.FIELDS[name].expr), list(p[:3])] for name, p in points.items()})
    want = {}
    for name, (u, v, component, distance) in points.items():
        h = _h(name, k_u, k_v, "mpmath")
        with mpmath.workdps(30):
            height = abs(float(h(mpmath.mpf(u), mpmath.mpf(v))))
        h1, h3 = (abs(float(_partial(h, u, v, component, n))) for n in (1, 3))
        x = u if component == "u" else v
        below = DEFAULT_STEPS[DEFAULT_STEPS < distance]
        want[name] = dict(k_u=k_u, k_v=k_v, crease_distance=distance, steps=int(below.size),
                          largest_step=float(below.max()), h=height, h1=h1, x_h1=abs(x) * h1, h3=h3,
                          eps_model=(3 * UNIT_ROUNDOFF * (height + abs(x) * h1) / h3) ** (1 / 3))
    return got, want


@pytest.mark.parametrize("seed", [31, 32])
def test_the_optima_at_random_points_and_frequencies_are_mpmaths(seed, monkeypatch):
    got, want = _optima_route(seed, monkeypatch)
    for name, fields in want.items():
        assert {key: got[name][key] for key in fields} == pytest.approx(fields, rel=1e-7, abs=0), name


def test_optima_measured_with_the_frequencies_exchanged_are_caught(monkeypatch):
    """The wrong variant: the optimum's curve measured with k_u and k_v exchanged."""
    import renderer.ucurve as ucurve
    real = ucurve.measure
    monkeypatch.setattr(ucurve, "measure", lambda *a, k_u, k_v, **kw: real(*a, k_u=k_v, k_v=k_u, **kw))
    got, want = _optima_route(31, monkeypatch)
    assert any(got[name]["h1"] != pytest.approx(want[name]["h1"], rel=1e-7, abs=0) for name in want)


def _footprint_against_neighbours(scene, size=64):
    """Per interior sphere-A pixel of ``scene``: `accuracy.footprint_steps` over pbrt-v4's rule computed
    another way, half the sum of |u's change| across one pixel in x and in y, read off the G-buffer's chart
    at the neighbouring pixels (central differences of uv), away from the pole (where u turns fast), the
    silhouette and the seam u = 0 = 1."""
    g = gbuffer(scene, size, size)
    on_a = g.chamber == SPHERE_A
    u = g.uv[..., 0]
    du_x, du_y = (u[1:-1, 2:] - u[1:-1, :-2]) / 2, (u[2:, 1:-1] - u[:-2, 1:-1]) / 2
    inner = on_a[1:-1, 1:-1] & on_a[1:-1, 2:] & on_a[1:-1, :-2] & on_a[2:, 1:-1] & on_a[:-2, 1:-1]
    inner &= (g.N[1:-1, 1:-1, 2] < 0.9) & (g.N[1:-1, 1:-1, 2] > 0.3) & (np.maximum(abs(du_x), abs(du_y)) < 0.1)
    steps = np.zeros(on_a.shape)
    steps[on_a] = accuracy.footprint_steps(scene, size)
    return steps[1:-1, 1:-1][inner] / (0.5 * (abs(du_x) + abs(du_y)))[inner]


@pytest.mark.parametrize("scene", _scenes(2, seed=41), ids=lambda s: f"e{s.camera_z:.2f}")
def test_the_footprint_step_is_the_chart_distance_one_pixel_covers(scene):
    """On random scenes (the camera moved): the footprint steps Cell 2 histograms and §3's table takes the
    median of are, pixel by pixel, the chart's change across a pixel as the neighbouring pixels show it."""
    ratio = _footprint_against_neighbours(scene)
    assert ratio.size > 300
    assert np.median(ratio) == pytest.approx(1.0, abs=0.01) and np.quantile(abs(ratio - 1), 0.9) < 0.03


def test_a_footprint_step_without_its_half_is_caught(monkeypatch):
    """The wrong variant: |du/dx| + |du/dy|, pbrt-v4's rule without its factor 1/2."""
    footprint = pointwise.footprint
    monkeypatch.setattr(pointwise, "footprint", lambda *a: tuple(2 * x for x in footprint(*a)))
    assert np.median(_footprint_against_neighbours(_scenes(1, seed=41)[0])) == pytest.approx(2.0, abs=0.04)


def test_the_stored_footprint_median_is_the_median_of_the_footprint_steps():
    """§3's table and Cell 2 both show `accuracy.footprint_median`: at each size the median of the book
    scene's footprint steps.  The two sizes' medians differ, so a store that reused one size's value for
    another (the wrong variant) would fail an equality."""
    medians = {size: accuracy.footprint_median(size) for size in (16, 37)}
    assert medians == {size: np.median(accuracy.footprint_steps(Scene(), size)) for size in medians}
    assert medians[16] != medians[37]
