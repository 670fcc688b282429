"""The coordinates in which theorem displaced-normal (proofs/surface.py) checks its slopes are the ones
its steps describe: at the point, n, e_u and e_v an orthonormal frame with n = z and e_u = x, the
chart right-handed in one case and left-handed in the other, p_u and p_v of lengths |p_u| and |p_v|
along e_u and e_v; n_u and n_v tangent and otherwise free on an orthogonal chart, kappa times p_u and
p_v on a principal one.  The checker proves each step in these cases only, so a case that is not
what the step says (e_u of length 2, an orthogonal chart made principal, one handedness twice) would
prove a narrower or another statement (mutmut's survivors: mutants of ``_chart``, which runs at import)."""

import sympy as sp

from proofs import surface as S


def _frame(case):
    return case[S.N_S], case[S.EU_S], case[S.EV_S]


def test_each_case_is_an_orthonormal_frame_with_n_up_and_e_u_along_x():
    for label, case in S.ORTHOGONAL + S.PRINCIPAL_CHARTS:
        n, e_u, e_v = _frame(case)
        frame = sp.Matrix.hstack(n, e_u, e_v)
        assert sp.simplify(frame.T * frame) == sp.eye(3), label
        assert (n, e_u) == (sp.ImmutableMatrix([0, 0, 1]), sp.ImmutableMatrix([1, 0, 0])), label
        assert case[S.PU_S] == S.L_U * e_u and case[S.PV_S] == S.L_V * e_v, label


def test_both_handednesses_and_the_labels_say_which():
    for cases in (S.ORTHOGONAL, S.PRINCIPAL_CHARTS):
        signs = {}
        for label, case in cases:
            n, e_u, e_v = _frame(case)
            signs[label] = e_u.cross(e_v).dot(n)
        assert signs == {"a right-handed chart": 1, "a left-handed chart": -1}, signs


def test_an_orthogonal_chart_has_free_tangent_normal_derivatives_a_principal_one_kappa_p():
    for label, case in S.ORTHOGONAL:
        n, (n_u, n_v) = case[S.N_S], (case[S.NU_S], case[S.NV_S])
        assert n_u.dot(n) == 0 and n_v.dot(n) == 0, label                     # tangent
        free = [sorted(map(str, d.free_symbols)) for d in (n_u, n_v)]
        assert free == [["c1", "c2"], ["d1", "d2"]], (label, free)           # two free components each
        assert n_u.jacobian([S._c1, S._c2]).rank() == n_v.jacobian([S._d1, S._d2]).rank() == 2, label
    for label, case in S.PRINCIPAL_CHARTS:
        assert case[S.NU_S] == S.K_U * case[S.PU_S] and case[S.NV_S] == S.K_V * case[S.PV_S], label


def test_any_vectors_are_three_free_components_each():
    symbols = [s for vector in S.ANY_VECTORS.values() for s in vector]
    assert len(set(symbols)) == 3 * len(S.ANY_VECTORS) and all(isinstance(s, sp.Symbol) for s in symbols)
