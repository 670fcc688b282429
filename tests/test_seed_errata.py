"""lab/seed_errata.py: what each erratum counts, on inputs whose answer is known without it.

The errata's measurements run on the draft's scene (verify/test_errata.py checks that each
defect is there); here their counting rules are held to small planted cases: which
(pixel, light) pairs the draft's rule would light past the terminator, and on which spheres
the ungated lobe is counted.
"""

from types import SimpleNamespace

import numpy as np
import pytest

from lab import seed_errata
from renderer import DRAFT_SCENE
from renderer.render import BACKGROUND, SPHERE_A, SPHERE_B


def test_a_pair_in_a_cast_shadow_does_not_leak(monkeypatch):
    """The draft's rule lights a pair past the terminator only where its own cast-shadow test lets the light
    through: of four pairs whose geometric normal faces away from the light, the one behind sphere B and the
    one whose bumped normal faces away too do not count."""
    away, bumped = np.full(4, -0.5), np.array([0.3, 0.2, 0.4, -0.1])
    cast = np.array([False, True, False, False])

    def light_terms(scene, size):
        return [(scene.lights[0], away, bumped, cast)]
    monkeypatch.setattr(seed_errata, "_light_terms", light_terms)
    m = seed_errata._terminator_leak(size=8)
    assert (m["leak_pixels_default"], m["leak_pixels_beta_1_5"]) == (2, 2)


def test_the_largest_ungated_lobe_is_found_pixel_by_pixel(monkeypatch):
    """Two sphere-A pixels at different points, each facing away from the light with a lobe: both counted,
    and the largest lobe is the larger of the two computed by hand (each with its own light direction)."""
    scene = DRAFT_SCENE.replace(lights=DRAFT_SCENE.lights[:1])
    points = [np.array([0.2, 0.3, 0.9]), np.array([-0.6, 0.1, 0.75])]
    normals = [_facing_away(scene, P) for P in points]
    g = SimpleNamespace(chamber=np.array([[SPHERE_A, SPHERE_A]], dtype=np.uint8), P=np.array([points]),
                        Ns=np.array([normals]))
    monkeypatch.setattr(seed_errata, "DRAFT_SCENE", scene)
    monkeypatch.setattr(seed_errata, "gbuffer", lambda scene, w, h: g)
    found = seed_errata._specular_ungated(size=2)
    lobes = [_lobe(scene, P, Ns) for P, Ns in zip(points, normals)]
    assert found["pixels"] == 2 and found["max_specular_added"] == pytest.approx(max(lobes), rel=1e-12, abs=0)


def test_the_drafts_sphere_b_hits_lie_off_it_by_the_closed_form():
    """The draft's quadratic for sphere B keeps a t^2 + 2 b t and replaces c = |E - C|^2 - r^2 with |C|^2 - r^2, so
    at each of its roots |P - C|^2 - r^2 = |E - C|^2 - |C|^2 = e^2 - 2 e C_z: every hit lies the same distance
    sqrt(r^2 + e^2 - 2 e C_z) - r off the sphere (a number the errata show, here without the draft's code)."""
    e, (_, _, c_z), r = DRAFT_SCENE.camera_z, DRAFT_SCENE.center_b, DRAFT_SCENE.radius_b
    off = abs(np.sqrt(r * r + e * e - 2 * e * c_z) - r)
    m = seed_errata._sphere_b_seed_vs_true()
    assert m["off_surface_max"] == pytest.approx(off, rel=1e-12, abs=0)
    assert m["off_surface_relative"] == pytest.approx(off / r, rel=1e-12, abs=0)


@pytest.mark.parametrize("position", [(0.3, 0.3, 1.6), (0.45, 0.45, 1.05), (0.4, 0.45, 0.95), (0.2, 0.2, 1.2)],
                         ids=["B between", "B between, close", "B beyond the light", "B beyond, lower"])
def test_the_drafts_cast_shadow_is_sphere_b_cutting_the_segment(position):
    """The draft's quadratic for sphere B's cast shadow on A against a march of 2,000 points along each
    segment from the hit point to the light: lights with B between them and A, and lights between A and
    B, where the line meets B beyond the light (a root past 1, which casts no shadow)."""
    from renderer import gbuffer
    from renderer.scene import PointLight
    scene = DRAFT_SCENE.replace(lights=(PointLight(position, (1.0, 1.0, 1.0)),))
    [(_, _, _, cast)] = seed_errata._light_terms(scene, size=48)
    g = gbuffer(scene, 48, 48)
    P = g.P[g.chamber == SPHERE_A]
    s = np.linspace(0.0, 1.0, 2001)[1:-1, None, None]
    inside = np.linalg.norm(P + s * (np.asarray(position) - P) - np.asarray(scene.center_b), axis=-1) < scene.radius_b
    assert P.shape[0] > 1000 and np.count_nonzero(cast != inside.any(axis=0)) <= 2


def _lobe(scene, P, Ns):
    """The Blinn lobe the draft adds at P with shading normal Ns, by hand: k_s max(0, Ns . h)^n times the first
    light's brightest channel, h the half vector of the directions to that light and to the eye."""
    L, E = np.asarray(scene.lights[0].position), np.array([0.0, 0.0, scene.camera_z])
    w, v = (L - P) / np.linalg.norm(L - P), (E - P) / np.linalg.norm(E - P)
    return scene.ks * max(Ns @ ((w + v) / np.linalg.norm(w + v)), 0.0) ** scene.shininess * max(scene.lights[0].color)


def _facing_away(scene, P):
    """A shading normal at P that faces away from the first light while its half vector with the eye leans
    towards it: the draft adds a lobe there."""
    L, E = np.asarray(scene.lights[0].position), np.array([0.0, 0.0, scene.camera_z])
    w, v = (L - P) / np.linalg.norm(L - P), (E - P) / np.linalg.norm(E - P)
    h = (w + v) / np.linalg.norm(w + v)
    Ns = h - (h @ w) * w - 1e-3 * w
    return Ns / np.linalg.norm(Ns)


@pytest.mark.parametrize("codes, pairs", [((SPHERE_A, BACKGROUND), 1), ((BACKGROUND, SPHERE_B), 1),
                                          ((SPHERE_A, SPHERE_B), 2), ((BACKGROUND, BACKGROUND), 0)])
def test_the_ungated_lobe_is_counted_on_both_spheres(monkeypatch, codes, pairs):
    """Erratum specular-ungated counts the pairs of sphere A and of sphere B (the draft shades both with the
    same rule): a pixel of either, with a normal facing away from the light and a lobe, is one pair."""
    scene = DRAFT_SCENE.replace(lights=DRAFT_SCENE.lights[:1])
    P = np.array([0.2, 0.3, 0.9])
    Ns = _facing_away(scene, P)
    g = SimpleNamespace(chamber=np.array([codes], dtype=np.uint8), P=np.array([[P, P]]), Ns=np.array([[Ns, Ns]]))
    monkeypatch.setattr(seed_errata, "DRAFT_SCENE", scene)
    monkeypatch.setattr(seed_errata, "gbuffer", lambda scene, w, h: g)
    found = seed_errata._specular_ungated(size=2)
    assert found["pixels"] == pairs
    lobe = _lobe(scene, P, Ns)                            # none counted, none added
    assert lobe > 0 and found["max_specular_added"] == (pytest.approx(lobe, rel=1e-12, abs=0) if pairs else 0.0)


# ----------------------------------------------------------------------- the book's words for them
def test_each_erratum_is_worded_once_from_its_own_numbers():
    """book/chapter/errata_words.py: one title, correction and finding per erratum, in the register's
    order; each finding shows its own erratum's counts (a template reading another erratum's number,
    or a count typed in, fails here), and the errata are numbered E1, E2, ... with the draft's data."""
    import re

    from chapter.errata_words import WORDS, errata, finding
    assert list(WORDS) == [e.id for e in seed_errata.ERRATA]
    measured = seed_errata.measure_all()
    for e in seed_errata.ERRATA:
        text = finding(e.id, measured[e.id])
        read = re.findall(r"\{([^:}]+)", WORDS[e.id]["finding"])
        assert read and "{" not in text, e.id                  # every finding shows a measured number
        for key, x in measured[e.id].items():              # every count it measured, but one the book omits
            if isinstance(x, int) and (e.id, key) != ("sphere-b-quadratic", "seed_pixels_a"):
                assert f"{x:,}" in text, (e.id, key)
    md = errata(measured)
    assert re.findall(r"\*\*E(\d+)\. ", md) == [str(i) for i in range(1, len(seed_errata.ERRATA) + 1)]
    assert all(e.seed in md and e.where in md for e in seed_errata.ERRATA)
    with pytest.raises(KeyError, match="seed_pixels_b"):
        finding("sphere-b-quadratic", {"pixels": 1})
    with pytest.raises(KeyError, match="erratum_id must be one of"):
        finding("no-such-erratum", {})


# ----------------------------------------------------------------- the draft's values, spelled once
def test_the_draft_is_measured_with_its_own_values_not_the_books_defaults(monkeypatch):
    """`Scene`'s defaults (the book's) moved away from the draft's step, frequencies and β: the whole
    register of claims and the errata, measured afresh, render, take G-buffers and central differences
    only of scenes and at steps that are not the moved defaults (the draft's are read from `DRAFT_SCENE`,
    or are a value the draft's own cell names), every verdict stays the registered one and every erratum
    is still reproduced.  (A claim that built its frame from `Scene()` would show here.)"""
    import inspect

    from lab import accuracy, claims, store
    from renderer import pointwise
    from renderer.scene import Scene
    moved = {"eps": 2.5e-4, "beta": 0.21, "k_u": 3.0, "k_v": 5.0}
    names = list(inspect.signature(Scene.__init__).parameters)[1:]
    defaults = list(Scene.__init__.__defaults__)
    for name, value in moved.items():
        defaults[names.index(name)] = value
    monkeypatch.setattr(Scene.__init__, "__defaults__", tuple(defaults))
    assert Scene().eps == moved["eps"] and DRAFT_SCENE.eps != moved["eps"]
    scenes, stencils = [], []

    def spy(module, name):
        real = getattr(module, name)
        monkeypatch.setattr(module, name, lambda scene, *a, **k: scenes.append(scene) or real(scene, *a, **k))
    for module in (claims, seed_errata, accuracy):
        for name in {"render", "gbuffer"} & set(vars(module)):
            spy(module, name)
    central = pointwise.central_gradient

    def spied_central(f, u, v, ku, kv, eps, *a):
        stencils.append((ku, kv, eps))
        return central(f, u, v, ku, kv, eps, *a)
    monkeypatch.setattr(pointwise, "central_gradient", spied_central)
    monkeypatch.setattr(store, "_MEMORY", {})                  # measured afresh, not read from a store
    monkeypatch.delenv(store.ENV, raising=False)
    caches = (claims._frames_of, claims._ucurve, claims._errata)
    for cache in caches:
        cache.cache_clear()
    try:
        results, errata = claims.evaluate(), seed_errata.reproduced()
    finally:
        for cache in caches:
            cache.cache_clear()
    assert [(c.id, v, m) for c, m, v in results if v != c.registered] == []
    assert errata["v-border-branch"]["steps"][0] == DRAFT_SCENE.eps
    assert len(scenes) > 20 and len(stencils) > 2
    assert [s for s in scenes if any(getattr(s, k) == x for k, x in moved.items())] == []
    assert [s for s in stencils if {float(np.max(x)) for x in s} & set(moved.values())] == []
