"""The return mapping in C99: the text the ``c`` target writes after the law's local functions.

The algorithm is the one of the compiled return mapping (``contact/_return_kernel.py``),
line for line: elastic trial (4.2), separation, limit check, backward Euler solved by Newton's
method on the dimensionless residual with a backtracking line search, returns that end at the
apex of a cone, the consistent tangent (the σ-block of the inverse Jacobian times E), and the
substepping of :class:`~frictionrules.ContactModel` where Newton fails (halving).
The structured return (:mod:`._c_structured`, ``@STRUCTURED@``) comes first: where the law's
symbolic structure offers a radial return it answers without Newton's method, and hands the
contact to the general return otherwise (compiled with ``-D<NAME>_GENERAL_RETURN_ONLY``, the
general return takes every contact: the comparison of the tests).
``@NAME@`` is replaced by the function prefix, the other ``@...@`` by the numbers and codes of
:mod:`frictionrules._returnspec` (one home for every return mapping). The enum constants (``NQ``, ``SIZE``, the
offsets ``OFF_*``, ``CLIP``, ``HAS_KAPPA``, ``KAPPA``) and ``local_f``, ``local_first``, ``local_full`` come
before this text.
"""

CORE = r"""
#define TOL @TOL@
#define MAX_ITER @MAX_ITER@
#define MAX_HALVINGS @MAX_HALVINGS@
#define MAX_DEPTH @MAX_DEPTH@
#define SUFFICIENT_DECREASE @SUFFICIENT_DECREASE@
#define M (4 + NQ)
#define NQS (NQ > 0 ? NQ : 1)

enum { ELASTIC = @ELASTIC@, PLASTIC = @PLASTIC@, OPEN = @OPEN@, APEX = @APEX@, FAILED = @FAILED@ };

/* The law's quantities at (T1, T2, N, q) into w, made finite at kinks: a derivative that is
   not finite is the minimal-norm subgradient 0; a limit condition that is not finite is its
   largest value on a small circle around T (the kink rule). */
static void eval_law(double s0, double s1, double s2, const double *q, const double *p,
                     double *w, int level)
{
    const double n = CLIP ? fmax(s2, 0.0) : s2;
    int last = SIZE, k, j;
    if (level == 0) {
        local_f(s0, s1, n, q, p, w);
        last = 1;
    } else if (level == 1) {
        local_first(s0, s1, n, q, p, w);
    } else {
        local_full(s0, s1, n, q, p, w);
    }
    for (k = 1; k < last; k++)
        if (!isfinite(w[k]))
            w[k] = 0.0;
    if (!isfinite(w[0])) {
        const double r = @KINK_RADIUS@ * (sqrt(s0 * s0 + s1 * s1) + fabs(n)) + 1e-300;
        double best = -HUGE_VAL;
        for (j = 0; j < @KINK_POINTS@; j++) {
            const double a = @KINK_ANGLE@ * j;
            local_f(s0 + r * cos(a), s1 + r * sin(a), n, q, p, w);
            if (w[0] > best)
                best = w[0];
        }
        w[0] = best;
    }
}

/* Scaled backward-Euler residual at x = (sigma, q, dlam) into out; returns its norm (a huge
   finite number where a component is beyond 1e150, so that a line search rejects it). */
static double residual(const double *w, const double *x, const double *sig_tr, const double *qn,
                       const double *dv, const double *rows, double *out)
{
    const double lam = x[M - 1];
    double acc = 0.0, r;
    int a, j;
    for (a = 0; a < 3; a++) {
        r = (x[a] - sig_tr[a] + lam * dv[a] * w[OFF_DG + a]) * rows[a];
        out[a] = r;
        if (!(fabs(r) < 1e150))
            return 1e300;
        acc += r * r;
    }
    for (j = 0; j < NQ; j++) {
        r = (x[3 + j] - qn[j] - lam * w[OFF_H + j]) * rows[3 + j];
        out[3 + j] = r;
        if (!(fabs(r) < 1e150))
            return 1e300;
        acc += r * r;
    }
    r = w[0] * rows[M - 1];
    out[M - 1] = r;
    if (!(fabs(r) < 1e150))
        return 1e300;
    acc += r * r;
    return sqrt(acc);
}

/* Newton Jacobian of the residual in (sigma, q, dlam), unscaled, row-major M x M. */
static void jacobian(const double *w, double lam, const double *dv, double *J)
{
    const int m = 3 + NQ;
    int a, b, j, k;
    for (a = 0; a < 3; a++) {
        for (b = 0; b < 3; b++)
            J[a * M + b] = (a == b ? 1.0 : 0.0) + lam * dv[a] * w[OFF_HGG + 3 * a + b];
        for (j = 0; j < NQ; j++)
            J[a * M + 3 + j] = lam * dv[a] * w[OFF_HGQ + NQ * a + j];
        J[a * M + m] = dv[a] * w[OFF_DG + a];
    }
    for (j = 0; j < NQ; j++) {
        for (b = 0; b < 3; b++)
            J[(3 + j) * M + b] = -lam * w[OFF_DHS + 3 * j + b];
        for (k = 0; k < NQ; k++)
            J[(3 + j) * M + 3 + k] = (j == k ? 1.0 : 0.0) - lam * w[OFF_DHQ + NQ * j + k];
        J[(3 + j) * M + m] = -w[OFF_H + j];
    }
    for (b = 0; b < 3; b++)
        J[m * M + b] = w[OFF_DF + b];
    for (k = 0; k < NQ; k++)
        J[m * M + 3 + k] = w[OFF_DFQ + k];
    J[m * M + m] = 0.0;
}

/* LU factorization with partial pivoting in place; 0 when singular. */
static int factor(double *J, int *piv)
{
    int c, r, k, j;
    for (c = 0; c < M; c++) {
        double best = fabs(J[c * M + c]), inv;
        k = c;
        for (r = c + 1; r < M; r++)
            if (fabs(J[r * M + c]) > best) {
                best = fabs(J[r * M + c]);
                k = r;
            }
        piv[c] = k;
        if (best == 0.0 || !isfinite(best))
            return 0;
        if (k != c)
            for (j = 0; j < M; j++) {
                const double t = J[c * M + j];
                J[c * M + j] = J[k * M + j];
                J[k * M + j] = t;
            }
        inv = 1.0 / J[c * M + c];
        for (r = c + 1; r < M; r++) {
            double l;
            J[r * M + c] *= inv;
            l = J[r * M + c];
            if (l != 0.0)
                for (j = c + 1; j < M; j++)
                    J[r * M + j] -= l * J[c * M + j];
        }
    }
    return 1;
}

/* Solve with the factors of factor(), b overwritten by the solution. */
static void lu_solve(const double *J, const int *piv, double *b)
{
    int c, r, j;
    for (c = 0; c < M; c++) {
        const int k = piv[c];
        if (k != c) {
            const double t = b[c];
            b[c] = b[k];
            b[k] = t;
        }
    }
    for (r = 1; r < M; r++) {
        double acc = b[r];
        for (j = 0; j < r; j++)
            acc -= J[r * M + j] * b[j];
        b[r] = acc;
    }
    for (r = M - 1; r >= 0; r--) {
        double acc = b[r];
        for (j = r + 1; j < M; j++)
            acc -= J[r * M + j] * b[j];
        b[r] = acc / J[r * M + r];
    }
}

/* Newton return of sig_tr onto f = 0 from x = (sig_tr, qn, 0); 1 if converged. Leaves the
   last iterate in x and the law's quantities there in w. */
static int newton_return(const double *sig_tr, const double *qn, const double *p,
                         const double *dv, double *x, double *w)
{
    double xk[M], rows[M], cols[M], R[M], Rk[M], step[M], J[M * M], wk[SIZE] = {0.0};
    int piv[M], a, b, j, k, it, h, full = 1;
    const double F = fmax(sqrt(sig_tr[0] * sig_tr[0] + sig_tr[1] * sig_tr[1]
                               + sig_tr[2] * sig_tr[2]), 1e-300);
    double dfn, fs, gs, lam_s, merit;
    eval_law(sig_tr[0], sig_tr[1], sig_tr[2], qn, p, w, 2);
    dfn = sqrt(w[OFF_DF] * w[OFF_DF] + w[OFF_DF + 1] * w[OFF_DF + 1]
               + w[OFF_DF + 2] * w[OFF_DF + 2]);
    fs = fmax(dfn * F, 1e-300);
    gs = fmax(sqrt(pow(dv[0] * w[OFF_DG], 2) + pow(dv[1] * w[OFF_DG + 1], 2)
                   + pow(dv[2] * w[OFF_DG + 2], 2)), 1e-300);
    lam_s = F / gs;
    for (a = 0; a < 3; a++) {
        rows[a] = 1.0 / F;
        cols[a] = F;
        x[a] = sig_tr[a];
    }
    for (j = 0; j < NQ; j++) {
        const double qs = fmax(fmax(fabs(w[OFF_H + j]) * lam_s, fabs(qn[j])), 1e-300);
        rows[3 + j] = 1.0 / qs;
        cols[3 + j] = qs;
        x[3 + j] = qn[j];
    }
    rows[M - 1] = 1.0 / fs;
    cols[M - 1] = lam_s;
    x[M - 1] = 0.0;
    merit = residual(w, x, sig_tr, qn, dv, rows, R);
    for (it = 0; it < MAX_ITER; it++) {
        double alpha = 1.0;
        int accepted = 0;
        if (merit <= TOL)
            break;
        if (!full)
            eval_law(x[0], x[1], x[2], x + 3, p, w, 2);
        jacobian(w, x[M - 1], dv, J);
        for (a = 0; a < M; a++)
            for (b = 0; b < M; b++)
                J[a * M + b] *= rows[a] * cols[b];
        if (!factor(J, piv))
            return 0;
        for (a = 0; a < M; a++)
            step[a] = -R[a];
        lu_solve(J, piv, step);
        for (a = 0; a < M; a++)
            step[a] *= cols[a];
        for (h = 0; h < MAX_HALVINGS; h++) {
            double mk;
            for (a = 0; a < M; a++)
                xk[a] = x[a] + alpha * step[a];
            eval_law(xk[0], xk[1], xk[2], xk + 3, p, wk, 1);
            mk = residual(wk, xk, sig_tr, qn, dv, rows, Rk);
            if (isfinite(mk) && mk <= (1.0 - SUFFICIENT_DECREASE * alpha) * merit) {
                for (a = 0; a < M; a++) {
                    x[a] = xk[a];
                    R[a] = Rk[a];
                }
                for (k = 0; k < SIZE; k++)
                    w[k] = wk[k];
                merit = mk;
                full = 0;
                accepted = 1;
                break;
            }
            alpha *= 0.5;
        }
        if (!accepted)
            return 0;
    }
    return merit <= TOL && x[M - 1] >= 0.0;
}

/* Trial forces whose return ends at the apex sigma = 0 of a cone. */
static int apex_region(const double *sig_tr, const double *q, const double *p,
                       const double *dv, double *w)
{
    double gt, tt;
    eval_law(0.0, 0.0, 0.0, q, p, w, 0);
    if (w[0] != 0.0)
        return 0;
    eval_law(sig_tr[0], sig_tr[1], 0.0, q, p, w, 1);
    gt = sqrt(w[OFF_DG] * w[OFF_DG] + w[OFF_DG + 1] * w[OFF_DG + 1]);
    tt = sqrt(sig_tr[0] * sig_tr[0] + sig_tr[1] * sig_tr[1]);
    return w[OFF_DG + 2] > 0.0 && sig_tr[2] * dv[0] * gt <= tt * dv[2] * w[OFF_DG + 2];
}

@STRUCTURED@
/* The return of closed trial forces sig_tr (sig_tr[2] > 0) at the stiffnesses dv: ELASTIC
   (sig = sig_tr), PLASTIC (sig, q1, dlam and, when dsig is not NULL, dsigma/dsigma_trial
   row-major 3 x 3), APEX (a return that ends at the apex of a cone) or FAILED. */
static int general_return(const double *sig_tr, const double *qn, const double *p,
                          const double *dv, double *sig, double *q1, double *dlam, double *dsig);

static int @NAME@_return(const double *sig_tr, const double *qn, const double *p,
                         const double *dv, double *sig, double *q1, double *dlam, double *dsig)
{
    int a, j;
    for (j = 0; j < NQ; j++)
        q1[j] = qn[j];
    for (a = 0; a < 3; a++)
        sig[a] = sig_tr[a];
    *dlam = 0.0;
#ifndef @NAME_UPPER@_GENERAL_RETURN_ONLY
    a = structured_return(sig_tr, qn, p, dv[0], dv[2], sig, q1, dlam, dsig);
    if (a != GENERAL)
        return a;
#else
    (void)structured_return;
#endif
    return general_return(sig_tr, qn, p, dv, sig, q1, dlam, dsig);
}

/* The general return (Newton's method on the whole system), sig, q1 and dlam at the trial. */
static int general_return(const double *sig_tr, const double *qn, const double *p,
                          const double *dv, double *sig, double *q1, double *dlam, double *dsig)
{
    double x[M], w[SIZE] = {0.0}, J[M * M], col[M];
    int piv[M], a, c, j;
    const double ntr = sqrt(sig_tr[0] * sig_tr[0] + sig_tr[1] * sig_tr[1]
                            + sig_tr[2] * sig_tr[2]);
    eval_law(sig_tr[0], sig_tr[1], sig_tr[2], qn, p, w, 0);
    if (w[0] <= 0.0)
        return ELASTIC;
    if (!newton_return(sig_tr, qn, p, dv, x, w)) {
        if (sig_tr[2] <= TOL * ntr || apex_region(sig_tr, qn, p, dv, w))
            return APEX;
        return FAILED;
    }
    *dlam = x[M - 1];
    if (x[2] < 0.0 || sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) <= TOL * ntr)
        return APEX;
    for (a = 0; a < 3; a++)
        sig[a] = x[a];
    for (j = 0; j < NQ; j++)
        q1[j] = x[3 + j];
    if (dsig != NULL) {
        eval_law(x[0], x[1], x[2], x + 3, p, w, 2);
        jacobian(w, *dlam, dv, J);
        if (!factor(J, piv))
            return FAILED;
        for (c = 0; c < 3; c++) {
            for (a = 0; a < M; a++)
                col[a] = a == c ? 1.0 : 0.0;
            lu_solve(J, piv, col);
            for (a = 0; a < 3; a++)
                dsig[3 * a + c] = col[a];
        }
    }
    return PLASTIC;
}
"""

UPDATE = r"""
/* One backward-Euler step of the contact (no substeps): ELASTIC, PLASTIC, OPEN or FAILED. */
static int step_once(const double *params, const double *s, const double *du, double *out,
                     double *force, double *tangent)
{
    const double kt = params[0], kn = params[1];
    const double *p = params + 2;
    const double dv[3] = {kt, kt, kn};
    double et[3], sig_tr[3], sig[3] = {0.0, 0.0, 0.0}, q1[NQS], dsig[9], f[3], dlam;
    int kind = OPEN, apex = 0, a, b, j;
    for (a = 0; a < 3; a++)
        et[a] = s[a] + du[a];
    sig_tr[0] = kt * et[0];
    sig_tr[1] = kt * et[1];
    sig_tr[2] = -kn * et[2];
    for (j = 0; j < NQ; j++)
        q1[j] = s[6 + j];
    if (sig_tr[2] > 0.0) {
        kind = @NAME@_return(sig_tr, s + 6, p, dv, sig, q1, &dlam,
                             tangent != NULL ? dsig : NULL);
        if (kind == FAILED)
            return FAILED;
        if (kind == APEX) {
            apex = 1;
            kind = OPEN;
            for (j = 0; j < NQ; j++)
                q1[j] = s[6 + j];
        }
    }
    if (kind == OPEN) {
        sig[0] = sig[1] = sig[2] = 0.0;
        f[0] = 0.0;
        f[1] = 0.0;
        f[2] = fmax(et[2], 0.0);
    } else if (kind == ELASTIC) {
        f[0] = et[0];
        f[1] = et[1];
        f[2] = et[2];
    } else {
        f[0] = sig[0] / kt;
        f[1] = sig[1] / kt;
        f[2] = -sig[2] / kn;
    }
    for (a = 0; a < 3; a++) {
        out[a] = f[a];
        out[3 + a] = s[3 + a] + (et[a] - f[a]);
        force[a] = sig[a];
    }
    for (j = 0; j < NQ; j++)
        out[6 + j] = q1[j];
    if (apex && HAS_KAPPA)
        out[6 + KAPPA] = s[6 + KAPPA] + sqrt(et[0] * et[0] + et[1] * et[1]);
    if (tangent != NULL) {
        for (a = 0; a < 9; a++)
            tangent[a] = 0.0;
        if (kind == ELASTIC) {
            tangent[0] = kt;
            tangent[4] = kt;
            tangent[8] = -kn;
        } else if (kind == PLASTIC) {
            for (a = 0; a < 3; a++)
                for (b = 0; b < 3; b++)
                    tangent[3 * a + b] = dsig[3 * a + b] * (b < 2 ? kt : -kn);
        }
    }
    return kind;
}

void @NAME@_initial_state(double *state)
{
    int k;
    for (k = 0; k < @NAME_UPPER@_NSTATE; k++)
        state[k] = 0.0;
    @INITIAL@
}

int @NAME@_update(const double *params, const double *state_in, const double *increment,
                  double *state_out, double *force, double *tangent)
{
    const long full = 1L << MAX_DEPTH;
    double cur[@NAME_UPPER@_NSTATE], next[@NAME_UPPER@_NSTATE], du[3];
    long pos = 0;
    int depth = 0, kind, prev = ELASTIC, k;
    /* the whole step at once, as the first pass of the substepping below does */
    kind = step_once(params, state_in, increment, next, force, tangent);
    if (kind != FAILED) {
        for (k = 0; k < @NAME_UPPER@_NSTATE; k++)
            state_out[k] = next[k];
        return kind;
    }
    kind = ELASTIC;
    depth = 1;
    for (k = 0; k < @NAME_UPPER@_NSTATE; k++)
        cur[k] = state_in[k];
    while (pos < full) {
        const double frac = ldexp(1.0, -depth);
        int now;
        for (k = 0; k < 3; k++)
            du[k] = increment[k] * frac;
        now = step_once(params, cur, du, next, force, tangent);
        if (now == FAILED) {
            if (depth >= MAX_DEPTH)
                return FAILED;
            depth++;
            continue;
        }
        prev = kind;
        kind = now;
        for (k = 0; k < @NAME_UPPER@_NSTATE; k++)
            cur[k] = next[k];
        pos += full >> depth;
        while (depth > 0 && pos % (full >> (depth - 1)) == 0)
            depth--;
    }
    for (k = 0; k < @NAME_UPPER@_NSTATE; k++)
        state_out[k] = cur[k];
    return (kind == ELASTIC && prev == PLASTIC) ? PLASTIC : kind;
}
"""
