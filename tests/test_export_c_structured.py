"""The structured return of the ``c`` target (``_export/_c_structured.py``) against the general
Newton return of the same file and against :meth:`ContactModel.update`.

The structured return is the radial return of the law's symbolic structure: for Coulomb in
closed form, :math:`T = T^{tr}\\,\\mu N/|T^{tr}|` (the return (4.3) onto the cone f = 0 of (4.1)
along the flow of the trial, Δλ = f_tr/k_t), for slip hardening (4.5) one scalar equation
solved by Newton's iteration. Each law's file is compiled twice, as written and with
``-D<NAME>_GENERAL_RETURN_ONLY`` (the general return alone), and the two are run on the same
random paths with floating-point traps on: forces, states and tangents agree with each other
and with the library's backward Euler to 1e-12 of the trial force (Newton's tolerance is 1e-13
of it), including returns that end at the apex of the cone, opening, and the
frictionless cone μ = 0 (T = 0: the normal response alone).
"""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import frictionrules as fr
from _export_harness import C_FLAGS, CKernel, compiler, fpe_traps

KT, KN = 100.0, 200.0
#: name -> (law, hardening, structure the generator must recognise)
LAWS = {
    "coulomb": (fr.Coulomb(0.3), None, "closed"),
    "dilatant": (fr.Coulomb(0.3, dilatant=True), None, "closed"),
    "frictionless": (fr.Coulomb(0.0), None, "closed"),
    "hardening": (fr.Coulomb(0.3), fr.SlipHardening(0.2, 0.05), "scalar"),
    "elliptic": (fr.EllipticOrthotropic(0.6, 0.3, angle=0.4), None, "general"),
}


def _compile(folder, name, general_only):
    import subprocess
    lib = folder / (f"{name}_general.so" if general_only else f"{name}.so")
    flags = [f"-D{name.upper()}_GENERAL_RETURN_ONLY"] if general_only else []
    cmd = [compiler("c"), *C_FLAGS, *flags, "-o", str(lib), str(folder / f"{name}.c"), "-lm"]
    out = subprocess.run(cmd, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    import ctypes
    return ctypes.CDLL(str(lib.resolve()))


@pytest.fixture(scope="module")
def kernels(tmp_path_factory):
    cache = {}

    def get(key):
        if key not in cache:
            law, hard, _ = LAWS[key]
            folder = tmp_path_factory.mktemp(key)
            res = fr.export(law, "c", folder, kt=KT, kn=KN, hardening=hard, name=key)
            cache[key] = (CKernel(_compile(folder, key, False), key, res.nstatv),
                          CKernel(_compile(folder, key, True), key, res.nstatv),
                          fr.ContactModel(law, kn=KN, kt=KT, hardening=hard), np.array(res.props))
        return cache[key]
    return get


@pytest.mark.parametrize("key", sorted(LAWS))
def test_structure_recognised_from_the_symbolic_form(key):
    """Coulomb (either rule, any μ) has the closed-form radial return, slip hardening the
    scalar one, the elliptic section (elliptic, not radial) none in C: the general return."""
    from frictionrules._export._c_structured import structure_kind
    law, hard, kind = LAWS[key]
    law = fr.HardenedLaw(law, hard) if hard is not None else law
    assert structure_kind(law.symbolic_form()) == kind


def _run(key, kernels, path):
    """Drive the three along ``path``; assert agreement at every step; return the statuses."""
    fast, general, model, params = kernels(key)
    s_fast, s_gen, state = fast.initial_state(), general.initial_state(), model.initial_state()
    statuses = []
    for du in path:
        du = np.asarray(du, dtype=float)
        r = model.update(state, du, tangent=True)
        with fpe_traps():
            rc, s1, force, tan = fast.update(params, s_fast, du)
            rg, g1, gforce, gtan = general.update(params, s_gen, du)
        e = state.elastic + du
        scale = max(np.abs(r.force).max(), KT * np.hypot(e[0], e[1]), KN * abs(e[2]), 1e-300)
        # a step that starts on f = 0 is elastic or a return of Δλ ~ 0 by round-off: the
        # status may differ from the library's there, the forces may not
        for other in (rg, int(r.status)):
            assert rc == other or {rc, other} == {0, 1}, (rc, rg, r)
        for other in (gforce, r.force):
            assert np.abs(force - other).max() <= 1e-12 * scale, (force, other)
        for other in (g1[:6], np.r_[r.state.elastic, r.state.plastic]):
            assert np.abs(s1[:6] - other).max() <= 1e-12 * scale / min(KT, KN)
        q = np.ravel(model.law_state(r.state).values)
        assert np.allclose(s1[6:], q, rtol=1e-12, atol=1e-12 * max(1.0, np.abs(q).max(initial=0)))
        if rc == rg == 1 and key != "frictionless":  # the general return's tangent at μ = 0: below
            assert np.abs(tan - gtan).max() <= 1e-9 * max(KT, KN)
        statuses.append(rc)
        s_fast, s_gen, state = s1, g1, r.state
    return statuses


_increment = st.tuples(st.floats(-0.01, 0.01), st.floats(-0.01, 0.01), st.floats(-0.004, 0.003))


@pytest.mark.parametrize("key", sorted(LAWS))
@settings(max_examples=25, deadline=None)
@given(path=st.lists(_increment, min_size=1, max_size=6))
@example(path=[(0.0, 0.0, -0.01), (0.02, 0.0, 0.0), (-0.03, 0.01, 0.0), (0.0, 0.0, 0.02)])
def test_structured_return_equals_newton_and_contact_model_eq_4_3(key, kernels, path):
    """Random paths from a closed start (the first increment closes by 0.01): the structured C
    return, the general C return and ``ContactModel.update`` agree (Eqs. 4.2, 4.3, 4.5)."""
    _run(key, kernels, [(0.0, 0.0, -0.01)] + list(path))


def test_frictionless_cone_is_the_normal_response_alone(kernels):
    """μ = 0: a sliding step gives T = 0 exactly and N = -kn δn (no substepping at the
    degenerate cone), status slip, the whole tangential increment plastic."""
    fast, _, _, params = kernels("frictionless")
    s = fast.initial_state()
    with fpe_traps():
        rc0, s, _, _ = fast.update(params, s, np.array([0.0, 0.0, -0.01]))
        rc, s1, force, _ = fast.update(params, s, np.array([0.003, -0.001, 0.002]))
    assert (rc0, rc) == (0, 1)
    assert force[0] == 0.0 and force[1] == 0.0 and force[2] == pytest.approx(KN * 0.008, rel=1e-14)
    assert np.allclose(s1[3:5], [0.003, -0.001], rtol=1e-14)
    with fpe_traps():
        _, _, _, tan = fast.update(params, s, np.array([0.003, -0.001, 0.002]))
    assert np.array_equal(tan, np.diag([0.0, 0.0, -KN]))


@pytest.mark.parametrize("key", ["coulomb", "hardening", "frictionless"])
def test_apex_and_opening(key, kernels):
    """A slip at N ~ 1e-14 of |T| returns to the apex of the cone (reported open: the general
    return decides it), then sliding under compression, then opening; all three paths agree."""
    statuses = _run(key, kernels, [(0.0, 0.0, -1e-16), (0.05, 0.0, 0.0), (0.0, 0.0, -0.002),
                                   (0.01, 0.003, 0.0), (0.0, 0.0, 0.05)])
    assert statuses[1] == 2 and statuses[3] == 1 and statuses[4] == 2


AXIS_LAWS = {
    "coulomb": fr.Coulomb(0.3),
    "dilatant": fr.Coulomb(0.3, dilatant=True),
    "hardening": fr.HardenedLaw(fr.Coulomb(0.3), fr.SlipHardening(0.2, 0.05)),
    "user_hardening": fr.UserLaw("sqrt(T1**2 + T2**2) - mu*(1 + h*(1 - exp(-kappa/kh)))*N",
                                 potential="sqrt(T1**2 + T2**2)",
                                 params={"mu": 0.3, "h": 0.6, "kh": 0.004},
                                 state={"kappa": 0.0}, rates={"kappa": "slip"}),
    "user_dilatant": fr.UserLaw("sqrt(T1**2+T2**2) - mu*N", potential="sqrt(T1**2+T2**2) - beta*N",
                                params={"mu": 0.3, "beta": 0.1}),
}


def _values(pieces, inputs):
    """Every output of the programs ``pieces`` at ``inputs`` (by symbol name), in order."""
    import sympy
    values = dict(inputs)
    for _, prog in pieces:
        for sym, expr in (*prog.temps, *prog.outputs):
            expr = sympy.sympify(expr)
            sub = {s: sympy.Float(values[s.name], 30) for s in expr.free_symbols}
            values[str(sym)] = float(expr.xreplace(sub).evalf(30))
    return values


@pytest.mark.parametrize("key", sorted(AXIS_LAWS))
def test_axis_pieces_are_the_radial_return_at_T2_zero(key):
    """``step_programs(form, axis=True)`` (the LAMMPS pair style's return of a law that depends
    on T through |T| only, its trial on the frame's axis): f, the radial return's outputs
    (4.3, 4.5) and φ, φ' along it equal the general pieces at x1 = 0 < x0 (y1 = 0, y0 of either
    sign), to 1e-13; the axis pieces take no square root of x0² (Coulomb's y0 is μN)."""
    from frictionrules._export._lammps import isotropic
    from frictionrules._export._spec import law_spec
    from frictionrules.codegen import step_programs
    law = AXIS_LAWS[key]
    form = law.symbolic_form()
    assert isotropic(law_spec(law, kt=KT, kn=KN))
    general, axis = dict(step_programs(form)), dict(step_programs(form, axis=True))
    assert "radial" in general and set(axis) == set(general) - {"tangent"}
    rng = np.random.default_rng(7)
    for _ in range(5):
        inputs = {"x0": rng.uniform(0.1, 5.0), "x1": 0.0, "x2": rng.uniform(0.5, 5.0),
                  "kt": KT, "kn": KN, "lam": rng.uniform(0.0, 0.01),
                  "y0": rng.uniform(-2.0, 2.0), "y1": 0.0, "y2": rng.uniform(0.5, 5.0)}
        inputs |= {f"p{k}": float(v) for k, v in enumerate(form.values)}
        for j in range(len(form.state)):
            inputs |= {f"q{j}": rng.uniform(0.0, 0.01), f"u{j}": rng.uniform(0.0, 0.01),
                       f"h{j}": rng.uniform(0.5, 1.5)}
        inputs |= {f"v{i}": rng.uniform(-1.0, 1.0) for i in range(3)} | {"v1": 0.0}
        names = [n for piece in axis.values() for n, _ in piece.outputs]
        got = _values([(k, axis[k]) for k in axis], inputs)
        want = _values([(k, general[k]) for k in general if k != "tangent"], inputs)
        for n in names:
            assert got[n] == pytest.approx(want[n], rel=1e-13, abs=1e-13), (n, got[n], want[n])
    if key == "coulomb":
        assert {str(e) for n, e in axis["radial"].outputs if n == "y0"} <= {"a0", "p0*x2"}
