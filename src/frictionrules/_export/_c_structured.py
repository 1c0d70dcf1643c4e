r"""The structured return in C99: the return a law's symbolic structure offers without Newton's
method on the whole system, printed into the ``c`` target before the general return.

The structure is recognised from the law's symbolic form
(:func:`frictionrules.codegen.return_structure`) and its straight-line pieces are those of the
compiled step (:func:`frictionrules.codegen.step_programs`, printed for Numba by
:mod:`frictionrules.contact._step_source`): a radial return,
:math:`\sigma = \sigma^{tr} + \Delta\lambda v`, :math:`q = q_n + \Delta\lambda h` along the flow
direction of the trial (Eqs. 4.2, 4.3, 4.5), with :math:`\Delta\lambda = -f^{tr}/\phi'(0)` in
closed form where f is linear along it (Coulomb with either rule: the radial return onto the
cone) and by Newton's iteration on the one scalar equation :math:`\phi(\Delta\lambda) = 0`
otherwise (slip hardening), and its consistent tangent from the derivative of that map.

``structured_return`` answers ELASTIC, PLASTIC or GENERAL; GENERAL hands the contact to the
general return (the Newton return of :mod:`._c_template`) exactly where the compiled step
does: f not finite at the trial (the kink rule), a slope that does not fall, Δλ < 0, N <= 0
at the end, a tangential force that would reverse, a return that ends at the apex
(:math:`|\sigma| \le TOL\,|\sigma^{tr}|`), a scalar iteration that does not converge. One
case is taken here that the compiled step leaves to the general return: a return that ends
exactly on the cone's axis, :math:`T = 0` with N > 0 (the frictionless cone μ = 0: the normal
response alone, where the general return would substep at the degenerate cone).

Laws with another structure (elliptic, affine flow, none) get a ``structured_return`` that
answers GENERAL at once (the compiler removes it).

``structured_return_axis`` (``axis=True``, for a law that depends on T through :math:`|T|`
only) is the same return for a trial on the axis of its frame, :math:`T_2 = 0 < T_1`: the
pieces of :func:`frictionrules.codegen.step_programs` on the axis, where :math:`|T|` is
:math:`T_1` (Coulomb's return is :math:`T_1 = \mu N`: no root, no quotient), without the
tangent. The LAMMPS pair style takes the frame of an isotropic law along the trial's
tangential displacement, so every closed contact it updates is such a trial.
"""

from __future__ import annotations

__all__ = ["structured_c", "structure_kind"]

_HEAD = """/* The return the law's structure offers (radial, closed form or one scalar equation), before
   the general return: ELASTIC, PLASTIC (sig, q1, dlam and, when dsig is not NULL,
   dsigma/dsigma_trial) or GENERAL (the general return takes the contact). */
#define GENERAL @GENERAL@
static @INLINE@int structured_return(const double *sig_tr, const double *q, const double *p,
                             double kt, double kn, double *sig, double *q1, double *dlam,
                             double *dsig)
{"""

_HEAD_AXIS = """/* structured_return for a trial on the axis of its frame, sig_tr[1] = 0 < sig_tr[0] (this law
   depends on T through |T| only): the same answers, without the tangent. */
static inline int structured_return_axis(const double *sig_tr, const double *q, const double *p,
                                         double kt, double kn, double *sig, double *q1,
                                         double *dlam)
{"""

#: At the end of a radial return: the conditions of the compiled step (Δλ >= 0, N > 0, T does
#: not reverse, not at the apex), T landing exactly on the axis accepted.
_END = """    if (!(lam >= 0.0 && y2 > 0.0 && (y0 * x0 + y1 * x1 > 0.0 || (y0 == 0.0 && y1 == 0.0))
          && y0 * y0 + y1 * y1 + y2 * y2 > TOL * TOL * (x0 * x0 + x1 * x1 + x2 * x2)))
        return GENERAL;"""

_SCALAR = """    if (!(slope < 0.0))
        return GENERAL;
    double lam = -f / slope;
    const double fs = fnorm * sqrt(x0 * x0 + x1 * x1 + x2 * x2);
    double @YU@;
    for (int it = 0;; it++) {
        if (it == SCALAR_MAX_ITER || !(lam >= 0.0))
            return GENERAL;
@PATH@
        {
@ALONG@
            if (fabs(phi) <= TOL * fs)
                break;
            if (!(dphi < 0.0))
                return GENERAL;
            lam -= phi / dphi;
        }
    }"""


def structure_kind(form) -> str:
    """``"closed"`` (radial, closed form), ``"scalar"`` (radial, one scalar equation) or
    ``"general"`` (the general return only): what :func:`structured_c` prints for ``form``."""
    from ..codegen import step_programs
    names = dict(step_programs(form))
    if "radial" not in names:
        return "general"
    return "scalar" if "along" in names else "closed"


def structured_c(spec, inline: bool = False, axis: bool = False) -> str:
    """The C text of ``structured_return`` for the law of ``spec`` (a
    :class:`~frictionrules._export._spec.LawSpec`); ``static inline`` with ``inline`` (a
    header's copy, which the LAMMPS pair style compiles into its contact loop). With ``axis``,
    ``structured_return_axis`` (static inline; empty where the return is not radial): for a
    law that depends on T through :math:`|T|` only, which the caller checks."""
    from .._returnspec import GENERAL, SCALAR_MAX_ITER
    from ..codegen import c_block, step_programs, used_inputs
    prefix, nq = spec.name, spec.nq
    kind = structure_kind(spec.form)
    if axis:
        if kind == "general":
            return ""
        head = _HEAD_AXIS
    else:
        head = _HEAD.replace("@GENERAL@", str(GENERAL)).replace("@INLINE@",
                                                                "inline " if inline else "")
    if kind == "general":
        return head + "\n" + "\n".join(
            f"    (void){a};" for a in ("sig_tr", "q", "p", "kt", "kn", "sig", "q1", "dlam",
                                       "dsig")) + "\n    return GENERAL;\n}\n"
    pieces = dict(step_programs(spec.form, axis=axis))
    used = set()
    for prog in pieces.values():
        used |= used_inputs(prog)
    lines = [head, f"#define SCALAR_MAX_ITER {SCALAR_MAX_ITER}",
             "    const double x0 = sig_tr[0], x1 = {}, x2 = sig_tr[2];".format(
                 "0.0" if axis else "sig_tr[1]")]
    lines += [f"    const double q{j} = q[{j}];" for j in range(nq) if f"q{j}" in used]
    lines += [f"    const double p{k} = p[{k}];" for k in range(len(spec.param_names))
              if f"p{k}" in used]
    lines += ["    (void)q;", "    (void)p;", "    (void)kn;", "    (void)q1;"]
    lines += c_block(pieces["trial"], "    ", prefix)
    # NaN and -inf (the kink rule) go to the general return, as +inf does below.
    lines += ["    if (!(f > 0.0))", "        return (f <= 0.0 && f > -HUGE_VAL) ? ELASTIC : GENERAL;",
              "    if (!(f < HUGE_VAL))", "        return GENERAL;"]
    lines += c_block(pieces["radial"], "    ", prefix)
    if kind == "closed":
        lines += ["    if (!(slope < 0.0))", "        return GENERAL;"]
    else:
        yu = [f"y{i}" for i in range(3)] + [f"u{j}" for j in range(nq)]
        path = [f"        y{i} = x{i} + lam * v{i};" for i in range(3)]
        path += [f"        u{j} = q{j} + lam * h{j};" for j in range(nq)]
        lines.append(_SCALAR.replace("@YU@", ", ".join(yu)).replace("@PATH@", "\n".join(path))
                     .replace("@ALONG@", "\n".join(c_block(pieces["along"], " " * 12, prefix))))
    lines.append(_END)
    lines += [f"    sig[{i}] = y{i};" for i in range(3)]
    lines += [f"    q1[{j}] = u{j};" for j in range(nq)]
    lines += ["    *dlam = lam;"]
    if axis:
        return "\n".join(lines + ["    return PLASTIC;", "}", "#undef SCALAR_MAX_ITER", ""])
    lines += ["    if (dsig != NULL) {"]
    lines += c_block(pieces["tangent"], "        ", prefix)
    # the tangent piece is d(sigma)/d(delta) = d(sigma)/d(sigma_tr) E, E = (kt, kt, -kn)
    lines += [f"        dsig[{3 * i + j}] = tan{i}{j} / {('kt', 'kt', '(-kn)')[j]};"
              for i in range(3) for j in range(3)]
    lines += ["    }", "    return PLASTIC;", "}", "#undef SCALAR_MAX_ITER", ""]
    return "\n".join(lines)
