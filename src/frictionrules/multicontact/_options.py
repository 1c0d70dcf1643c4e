r"""Solver schedules as named options records, and what a solver reports per iteration.

Every number a solver loop uses is a field here, with the measurements behind its default.
Pass one record to :func:`~frictionrules.solve` with ``options=``; its type selects nothing:
the ``method`` argument does, and the record must match it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_scalar

__all__ = ["NSGSOptions", "NewtonOptions", "ProxOptions", "ADMMOptions", "PolishOptions", "IterationInfo"]


def _check(record, positive=(), nonnegative=(), fractions=(), integers=(), counts=()) -> None:
    """Validate the named fields of a frozen options record (raise naming the field):
    ``integers`` >= 0, ``counts`` >= 1."""
    name = type(record).__name__
    for f in positive:
        check_scalar(f"{name}.{f}", getattr(record, f), lo=0.0, lo_open=True)
    for f in nonnegative:
        check_scalar(f"{name}.{f}", getattr(record, f), lo=0.0)
    for f in fractions:
        check_scalar(f"{name}.{f}", getattr(record, f), lo=0.0, hi=1.0, lo_open=True, hi_open=True)
    for f, least in [(f, 0) for f in integers] + [(f, 1) for f in counts]:
        value = getattr(record, f)
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
            raise FrictionRulesError(f"{name}.{f} = {value!r} violates: an integer >= {least}")


@dataclass(frozen=True)
class NSGSOptions:
    """Non-smooth Gauss–Seidel (``method="nsgs"``).

    Attributes
    ----------
    max_check_interval : int
        Largest number of sweeps between two evaluations of the full error (one product with
        W each); the interval is otherwise predicted from the observed linear rate.
    chunk_seconds : float
        The compiled sweeps run in chunks of about this wall time, between which the callback
        is called and the time limit checked.
    """

    max_check_interval: int = 16
    chunk_seconds: float = 0.25

    def __post_init__(self):
        _check(self, positive=("chunk_seconds",), counts=("max_check_interval",))


@dataclass(frozen=True)
class NewtonOptions:
    r"""Semismooth Newton on the Alart–Curnier function (``method="newton"``).

    Attributes
    ----------
    dense_max, dense_fill : int, float
        J is factorized dense (LAPACK) up to ``dense_max`` unknowns or above this fraction of
        nonzeros; SuperLU otherwise (its set-up costs more on small systems).
    refinement_steps : int
        Steps of iterative refinement with the same LU factors, so that one factorization
        gives a direction accurate to ``direction_rtol`` on an ill-conditioned J.
    direction_rtol : float
        A direction counts when :math:`|J x - b| \le` this :math:`\times |b|`; otherwise the
        Levenberg–Marquardt direction is taken.
    lm_weight : float
        Levenberg–Marquardt :math:`\lambda = ` ``lm_weight`` :math:`|\Phi|`.
    stall_iterations : int
        Levenberg–Marquardt directions while the merit has not halved over this many
        iterations (a singular J where W is rank-deficient and contacts stick).
    armijo, min_step, nonmonotone_memory : float, float, int
        Sufficient decrease, smallest step and memory of the non-monotone line search on
        :math:`\tfrac12|\Phi|^2`.
    restart_stall, restart_sweeps : int, int
        ``method="newton"``: when Siconos' error has not halved over ``restart_stall``
        iterations, ``restart_sweeps`` Gauss–Seidel sweeps (counted as iterations), then
        Newton again; 0 sweeps: never.
    """

    dense_max: int = 400
    dense_fill: float = 0.2
    refinement_steps: int = 3
    direction_rtol: float = 1e-10
    lm_weight: float = 1e-6
    stall_iterations: int = 4
    armijo: float = 2e-4
    min_step: float = 1e-8
    nonmonotone_memory: int = 10
    restart_stall: int = 40
    restart_sweeps: int = 5

    def __post_init__(self):
        _check(self, positive=("lm_weight", "direction_rtol", "min_step"), fractions=("dense_fill", "armijo"),
               integers=("dense_max", "refinement_steps", "stall_iterations", "restart_sweeps"),
               counts=("nonmonotone_memory", "restart_stall"))


@dataclass(frozen=True)
class ProxOptions:
    r"""Proximal point with an inner semismooth Newton (``method="prox"``).

    :math:`r_{k+1}` solves the problem :math:`(W + \sigma I, q - \sigma r_k)`.

    Attributes
    ----------
    sigma0 : float
        Initial :math:`\sigma` relative to the mean of diag W.
    shrink, grow : float
        Factor on :math:`\sigma` after an outer step that lowered / did not lower the error.
    inner_rtol : float
        The inner Newton stops at this fraction of the outer error.
    inner_max_iter : int
        Inner Newton iterations at most per outer step.
    newton : NewtonOptions
        Options of the inner Newton.

    Notes
    -----
    Chosen on the FCLIB files (outer iterations / factorizations, 0.3-0.03-0.03 against
    0.1-0.1-0.1): local_problem_test 6/19 vs 9/34, Capsules 4/16 vs 5/21, KaplasTower 5/8 vs
    6/10, PerioBox 4/15 vs 5/11, spheres-in-a-box 7/50 vs 27/241. The schedule is sensitive:
    ``sigma0 = 0.5`` fails on Capsules, ``inner_rtol = 0.05`` takes 81 outer iterations on
    spheres-in-a-box.
    """

    sigma0: float = 0.3
    shrink: float = 0.03
    grow: float = 4.0
    inner_rtol: float = 0.03
    inner_max_iter: int = 10
    newton: NewtonOptions = NewtonOptions()

    def __post_init__(self):
        _check(self, positive=("sigma0",), fractions=("shrink", "inner_rtol"), integers=("inner_max_iter",))
        check_scalar("ProxOptions.grow", self.grow, lo=1.0)
        if not isinstance(self.newton, NewtonOptions):
            raise FrictionRulesError(f"ProxOptions.newton = {self.newton!r} is not a NewtonOptions")


@dataclass(frozen=True)
class ADMMOptions:
    r"""ADMM on the cone-constrained problem with De Saxcé's correction (``method="admm"``).

    Iteration (scaled form, :math:`s = \mu(1 - d)|z_T| e_N` the correction from the current
    dual velocity z; Carpentier, Le Lidec & Montaut, RSS 2024):

    .. math::

        (W + (\rho + \eta) I)\,x^{k+1} = -(q + s) + \rho y^k + \eta x^k + z^k, \quad
        y^{k+1} = P_K(x^{k+1} - z^k/\rho), \quad z^{k+1} = z^k - \rho(x^{k+1} - y^{k+1}).

    The factorization of :math:`W + (\rho + \eta) I` is computed once per value of
    :math:`\rho`: an iteration costs one pair of triangular solves and O(nc), and one
    product with W where Siconos' error is measured (``max_check_interval``).

    Attributes
    ----------
    eta : float
        Proximal term :math:`\eta` relative to the largest eigenvalue L of W.
    rho_power : float
        Initial :math:`\rho = \sqrt{L m}\,(L/m)^{p}` with :math:`m = \eta L` (spectral rule).
    rho_stick : float
        Initial :math:`\rho / L` in the all-stick regime, where :math:`-(W + \rho I)^{-1} q`
        lies in every cone (0: the spectral rule always). Measured on KaplasTower, iterations
        to 1e-8 at a fixed :math:`\rho / L` of 1e-4, 3e-4, 1e-3, 1.6e-2 (spectral): 5, 6, 9,
        43; on local_problem_test (also all-stick) 386, 398, 1694, and over 2000.
    rho_power_step : float
        On an imbalance, :math:`\rho` is multiplied or divided by :math:`(L/m)^{step}`.
    ratio_primal_dual : float
        Imbalance threshold between the primal residual :math:`|x - y|_\infty` and the dual
        one :math:`|\rho\,\Delta y + \eta\,\Delta x|_\infty`.
    rho_update_every : int
        Iterations at least between two changes of :math:`\rho` (each one refactorizes).
    rho_levels_max : int
        Levels of :math:`\rho` (factors ``(L/m)^{rho_power_step}``) one change may take at
        most. Where the balance asks for a change the same way as the two or more before it,
        each made as soon as allowed (``rho_update_every``), the change is of
        :math:`2^{k-1}` levels after k of them (1: one level always). spheres-in-a-box's
        :math:`\rho` drifts down by eleven levels from the spectral start: 15 factorizations
        in 5000 iterations with 1, 9 with 8, the iterations to 1e-8 of the other shared
        files unchanged.
    rho_min, rho_max : float
        The residuals' balance does not move :math:`\rho / L` below ``rho_min`` nor above
        ``rho_max`` (Pinocchio clamps :math:`\rho` to [1e-6, 1e6]). Past the solution the
        balance drifts: KaplasTower (5 iterations to 1e-8) then halved :math:`\rho` every
        ``rho_update_every`` iterations, 25 factorizations in 120 iterations run at
        tolerance zero (7 with the band; PerioBox 12 and 7).
    anderson : int
        Memory of the Anderson acceleration of the fixed-point map on :math:`(y, z)`
        (0: none). An accelerated step is kept only when it lowers the fixed-point residual.
    anderson_pause : int
        After an accelerated step is dropped, the plain map runs alone until that many
        iterations have passed, and Anderson's memory starts again from there. Measured,
        iterations to 1e-8 without a pause / with 10 (5000 at most): Capsules 4396 / 450,
        local_problem_test 216 / 134, Spheres 61 / 71, Box_Stacks 40 / 46; to 1e-4 the 1,812
        pile 5000 (8.6e-4) / 1124, the 1,264-box pile 491 / 301. With 0, extrapolation
        starts again two iterations after each drop, and over a run such as Capsules' most
        tries are dropped (1069 of 2253; its iterations then depend on round-off: 2712 to
        4755 over eight draws of W and q perturbed by 1e-15, 450 on each with 10).
    anderson_pause_doublings : int
        The pause is doubled for each extrapolation dropped before it with none kept between,
        at most this many times (0: always ``anderson_pause``), so that Anderson's steps fade
        out where they keep failing. Measured, iterations to 1e-8 with 0 / 1 / 2: Capsules
        458 / 317 / 321, Spheres 71 / 69 / 69, local_problem_test 134 / 163 / 158, Box_Stacks
        and PerioBox unchanged (46, 14); left at 0 for local_problem_test.
    power_iterations : int
        Power iterations estimating L (only its order matters: 10 are within 1 % of 30 on
        KaplasTower).
    max_check_interval : int
        Siconos' error (one product with W, the costliest part of an iteration after the
        triangular solves on small problems) is evaluated where convergence is possible (the
        fixed-point residual below ``tol`` relative to :math:`\max(|q|, |y|)`), and otherwise
        at intervals predicted from the observed linear rate (half the predicted number of
        iterations to ``tol``), at most this many iterations apart (one more where the
        iteration due was an extrapolation dropped; 1: every iteration), as
        NSGS does (:attr:`NSGSOptions.max_check_interval`). The run's error history holds the
        iterations where it was measured. Only where the iteration runs compiled (no
        ``callback`` nor handover).
    """

    eta: float = 1e-6
    rho_power: float = 0.2
    rho_stick: float = 1e-4
    rho_power_step: float = 0.05
    ratio_primal_dual: float = 10.0
    rho_update_every: int = 5
    anderson: int = 5
    anderson_pause: int = 10
    anderson_pause_doublings: int = 0
    power_iterations: int = 10
    max_check_interval: int = 8
    rho_levels_max: int = 8
    rho_min: float = 1e-6
    rho_max: float = 1.0

    def __post_init__(self):
        _check(self, positive=("eta", "rho_power_step"), nonnegative=("rho_power", "rho_stick", "rho_min"),
               integers=("rho_update_every", "anderson", "anderson_pause", "anderson_pause_doublings",
                         "power_iterations"),
               counts=("max_check_interval", "rho_levels_max"))
        check_scalar("ADMMOptions.ratio_primal_dual", self.ratio_primal_dual, lo=1.0)
        check_scalar("ADMMOptions.rho_max", self.rho_max, lo=self.rho_min)


@dataclass(frozen=True)
class PolishOptions:
    r"""The polish stage (``method="polish"``; the last stage of ``"auto"``): semismooth Newton
    on De Saxcé's natural map with each contact's piece (open, stick, slip) read from the
    iterate.

    Attributes
    ----------
    contraction, patience : float, int
        The stage stops (reason ``"stalled"``) when the error has not fallen below
        ``contraction`` times its last value for ``patience`` consecutive steps: the active set
        has not settled. On a settled set the error falls quadratically.
    max_halvings : int
        Halvings of a step that does not lower Siconos' error before the stage stops.
    dense_max : int
        Up to this many unknowns J is factorized dense (LAPACK), SuperLU above.
    refinement_steps, direction_rtol : int, float
        Iterative refinement of a direction until its residual is below ``direction_rtol``
        times the right-hand side.
    regularization : float
        :math:`\sigma / \max|J_{ii}|` of the iterated Lavrentiev solve used where J is singular.
    """

    contraction: float = 0.5
    patience: int = 3
    max_halvings: int = 6
    dense_max: int = 400
    refinement_steps: int = 8
    direction_rtol: float = 1e-12
    regularization: float = 1e-9

    def __post_init__(self):
        _check(self, positive=("direction_rtol", "regularization"), fractions=("contraction",),
               integers=("max_halvings", "dense_max", "refinement_steps"), counts=("patience",))


@dataclass(frozen=True)
class IterationInfo:
    """What a solver hands the ``callback`` of :func:`~frictionrules.solve` after an iteration.

    Attributes
    ----------
    method : str
        The method running (``"admm"``, ...; a stage of ``"auto"``).
    iteration : int
        Iterations of that method so far (sweeps for nsgs).
    error : float
        Siconos' error of the current reactions.
    seconds : float
        Wall time since the solve started.
    """

    method: str
    iteration: int
    error: float
    seconds: float
