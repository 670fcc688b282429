"""The errata of the seed's code: each measured defect is real in the seed's
variant and absent from the renderer.  If a measurement stops showing its
defect, the book's errata section would be false: this fails first."""

import numpy as np
import pytest

from lab.seed_errata import ERRATA, ErratumVanished, reproduced
from renderer import DRAFT_SCENE, gbuffer
from renderer.render import SPHERE_A, SPHERE_B

def test_every_erratum_is_measured_and_reported(errata):
    assert [e.id for e in ERRATA] == list(errata)
    from chapter.errata_words import finding
    for e in ERRATA:
        text = finding(e.id, errata[e.id])
        assert text and "{" not in text


def test_sphere_b_seed_variant_is_off_the_surface(errata):
    m = errata["sphere-b-quadratic"]
    assert m["off_surface_relative"] > 1.0            # seed: points far off sphere B
    assert m["seed_pixels_b"] > 5 * m["true_pixels_b"]
    # The renderer's own sphere-B hit points are on the surface.
    scene = DRAFT_SCENE
    g = gbuffer(scene, 128, 128)
    b = g.chamber == SPHERE_B
    dist = np.linalg.norm(g.P[b] - np.asarray(scene.center_b), axis=-1)
    assert np.max(np.abs(dist - scene.radius_b)) <= 1e-12 * scene.radius_b


def test_terminator_leak_exists_in_seed_rule_only(errata):
    m = errata["terminator-leak"]
    assert m["leak_pixels_default"] > 0 and m["leak_diffuse_max_default"] > 1 / 255
    # The renderer: with one light and no ambient, every sphere-A pixel whose
    # geometric normal faces away from the light is exactly black.
    from renderer import render
    light = DRAFT_SCENE.lights[0]
    scene = DRAFT_SCENE.replace(lights=(light,), ka=0.0, beta=1.5)
    g = gbuffer(scene, 128, 128)
    image = render(scene, 128, 128).image
    a = g.chamber == SPHERE_A
    away = a & (np.einsum("hwc,hwc->hw", g.N, np.asarray(light.position) - g.P) <= 0)
    bumped_toward = away & (np.einsum("hwc,hwc->hw", g.Ns, np.asarray(light.position) - g.P) > 0)
    assert bumped_toward.sum() > 0          # pixels the seed's rule would light
    assert np.all(image[away] == 0.0)


def test_acos_pole_loses_digits_atan2_does_not(errata):
    m = errata["acos-pole"]
    assert m["max_rel_error_acos"] > 1e-3
    assert m["max_rel_error_atan2"] < 1e-14


def test_fallback_orientation_is_reflected(errata):
    m = errata["fallback-orientation"]
    assert m["orientation_fallback"] == 1.0 and m["orientation_fallback_south"] == -1.0
    assert m["orientation_regular_max"] == pytest.approx(-1.0, abs=1e-12)


def test_v_border_branch_fires_in_interior(errata):
    m = errata["v-border-branch"]
    assert m["steps"] == sorted(m["steps"], reverse=True) and len(m["steps"]) == 3
    assert 0 < m["fraction_interior"][0] < m["fraction_interior"][-1]
    # The change is the rounding of v +- eps over the step: each smaller step changes the quotient more.
    assert 0 < m["rel_change"][0] < m["rel_change"][1] < m["rel_change"][2]
    # Where it fires, the rounded span is the better divisor (what §6 says, at the middle step): nearer at
    # most pixels.
    assert 0.5 < m["nearer"][1] <= 1.0


def test_every_erratum_is_present_by_its_criterion(errata):
    assert reproduced(errata) is errata
    assert all(e.criterion and e.present(errata[e.id]) for e in ERRATA)


#: One case per condition of each erratum's criterion, at the edge where that condition stops holding (a
#: value, or a function of the measurement): the criterion must refuse every one.
VANISHED = [
    ("sphere-b-quadratic", "off_surface_relative", 1.0),
    ("sphere-b-quadratic", "seed_pixels_b", lambda m: 5 * m["true_pixels_b"]),
    ("terminator-leak", "leak_pixels_default", 0),
    ("terminator-leak", "leak_diffuse_max_default", 1 / 255),
    ("specular-ungated", "pixels", 0),
    ("specular-ungated", "max_specular_added", 0.0),
    ("v-border-branch", "fraction_interior", [0.0, 0.1, 0.2]),
    ("v-border-branch", "fraction_interior", [0.2, 0.2, 0.2]),
    ("acos-pole", "max_rel_error_acos", 1e-3),
    ("acos-pole", "max_rel_error_atan2", 1e-14),
    ("fallback-orientation", "orientation_fallback", -1.0),
    ("fallback-orientation", "orientation_regular_min", -1.0 - 2e-12),
    ("fallback-orientation", "orientation_regular_max", -1.0 + 2e-12),
]


@pytest.mark.parametrize("erratum_id, key, fixed", VANISHED)
def test_a_vanished_erratum_fails_the_book(erratum_id, key, fixed, errata):
    """The measurement of a corrected draft (its defect gone) is refused by name."""
    m = errata[erratum_id]
    gone = {**errata, erratum_id: {**m, key: fixed(m) if callable(fixed) else fixed}}
    with pytest.raises(ErratumVanished, match=erratum_id):
        reproduced(gone)


def test_report_rejects_a_missing_measurement():
    from chapter.errata_words import finding
    with pytest.raises(KeyError):
        finding(ERRATA[0].id, {})


def test_specular_lobe_is_gated_by_the_shading_normal():
    """Erratum specular-ungated: with only a specular term (kd = 0, low shininess),
    pixels lit geometrically but whose bumped normal faces away from the light
    are exactly black; the seed's rule would add ks (N'.h)^n there."""
    from renderer import render
    light = DRAFT_SCENE.lights[0]
    scene = DRAFT_SCENE.replace(lights=(light,), ka=0.0, kd=0.0, ks=1.0, shininess=1.0, beta=1.5,
                  sphere_b=False)
    g = gbuffer(scene, 128, 128)
    image = render(scene, 128, 128).image
    L = np.asarray(light.position)
    w = L - g.P
    w_hat = w / np.linalg.norm(w, axis=-1, keepdims=True)
    v = np.array([0.0, 0.0, scene.camera_z]) - g.P
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    h = w_hat + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    a = g.chamber == SPHERE_A
    lit = np.einsum("hwc,hwc->hw", g.N, w) > 0
    away = np.einsum("hwc,hwc->hw", g.Ns, w_hat) <= 0
    seed_lobe = np.maximum(np.einsum("hwc,hwc->hw", g.Ns, h), 0) ** scene.shininess
    target = a & lit & away & (seed_lobe > 1e-3)
    assert target.sum() > 0                      # the seed would light these visibly
    assert np.all(image[target] == 0.0)


def test_every_erratum_has_a_vanished_case():
    assert {e.id for e in ERRATA} == {case[0] for case in VANISHED}
