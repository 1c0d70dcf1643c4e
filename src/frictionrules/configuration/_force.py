r"""Force control: the displacements produced by prescribed horizontal forces ((3.7), (3.13)).

While the grain sticks, the loads it carries are those of its support (:mod:`.pockets`): in a
pocket the limit curve of its contacts as a facet set, on one contact that contact's limit with
the pull down the slope held by the pocket. The first force increment that leaves the support
defines the *limit point*: there the mechanism starts (one contact sliding, or two at once on a
ridge) and, because configuration softening makes :math:`h < 0`, the force cannot grow any
further — the run stops there. From a state on the limit curve of one sliding contact,
increments with :math:`\dot f_T \le 0` follow the active (softening) branch of the rate
relations,

.. math:: \dot\lambda = \frac{\dot f_T}{h},\qquad \dot u = \dot\lambda\, g_{,T},\qquad
          \dot z = -\dot\lambda\, g_{,Q},\qquad h = -f_{,u}\cdot g_{,T}

((3.5), (3.7), (3.13) re-derived; :class:`._contact.ContactTerms`), the choice the paper makes
("when the active process is performed"; rigid unloading is the other admissible answer).
Displacement control (:mod:`.path`) continues past the limit point in every case.
"""

from __future__ import annotations

import numpy as np

from ..errors import FrictionRulesError, check_vectors
from ._contact import contact_terms, finite_terms, require_sliding_law
from ._frame import frames
from .geometry import HEIGHT_TOL, angles, touching
from .pockets import Support, crossing
from .state import ForceControlResult, GrainState, LimitPoint

#: Forces within this fraction of ``Q`` of the limit curve are on it (round-off of the
#: mechanism solve).
FORCE_TOL = 1e-9


class _Sliding:
    """The grain sliding on one contact: its layer grain, and the configuration it moves."""

    def __init__(self, model, cid, centre, position, height):
        self.model, self.cid, self.centre = model, cid, np.asarray(centre, dtype=float)
        self.position, self.height = np.array(position, dtype=float), float(height)

    def offset(self) -> np.ndarray:
        return self.model.layer.offsets(self.position[None], self.centre[None])[0, 0]

    def terms(self, T, Q):
        d = self.model.diameter
        fr = frames(self.offset(), d, rates=True)
        return finite_terms(contact_terms(self.model.law, fr.axes, fr.rates, T, Q,
                                          self.model.layer.cylindrical), "force control")

    def state(self) -> GrainState:
        r = self.offset()
        d = self.model.diameter
        n = np.array([r[0], r[1], np.sqrt(max(d * d - r @ r, 0.0))]) / d
        a, p = angles(n, self.model.layer.cylindrical)
        return GrainState(self.position.copy(), self.height, (self.cid,), (float(a),), (float(p),))

    def check_alone(self, index: int) -> None:
        """Raise where the grain reaches another layer grain (a new contact closes): one higher
        than the sliding contact at the grain's position."""
        t = touching(self.model.layer, self.position)
        d = self.model.diameter
        r = self.offset()
        if t.height > np.sqrt(max(d * d - r @ r, 0.0)) + HEIGHT_TOL * d:
            raise FrictionRulesError(
                f"forces[{index}]: the grain reaches the layer grains {t.ids} at "
                f"{tuple(self.position)!r}; force control follows one sliding contact up to a "
                "new contact (use displacement control beyond)")


def force_path(model, forces, state: GrainState | None, Q: float) -> ForceControlResult:
    r"""Follow prescribed horizontal forces ``forces`` ``(n, 2)`` from ``state`` (default: the
    pocket) under the vertical load ``Q``; see the module's description."""
    T = check_vectors("forces", forces, (2,))
    if T.ndim != 2 or len(T) < 1:
        raise FrictionRulesError(f"forces must have shape (n, 2), got shape {T.shape}")
    require_sliding_law(model.law, f"{type(model).__name__}.force_path")
    support = Support.at(model, np.zeros(2) if state is None else state.position)
    tol = FORCE_TOL * Q
    f0 = float(support.limit(T[0], Q))
    if f0 > tol:
        raise FrictionRulesError(f"forces[0] = {tuple(T[0])!r} lies outside the limit curve "
                                 f"(f = {f0!r} > 0)")
    sliding = [f0 >= -tol]
    positions, heights = [support.position.copy()], [support.touching.height]
    grain: _Sliding | None = None
    limit = None
    completed = True

    def reach(i, s, force):
        """The limit point at ``force``; the sliding contact when one contact starts."""
        mech = support.mechanism(force, Q)
        if not mech.contacts:
            where = f"forces[{i + 1 if s > 0 else i}] = {tuple(force)!r}"
            if support.facets is not None:
                raise FrictionRulesError(f"{where}: no mechanism of the contacts "
                                         f"{support.touching.ids} starts at that force")
            raise FrictionRulesError(
                f"{where}: the force reaches the limit curve of contact {support.touching.ids[0]} "
                "where its in-plane part points down the slope: the grain would slide back into "
                "the pocket it comes from, which a one-contact model does not follow")
        lp = LimitPoint(i, float(s), np.array(force, dtype=float),
                        support.state(mech.contacts, heights[-1]), mech.velocity.copy())
        if len(mech.contacts) > 1 or not mech.quasi_static:
            return lp, None
        k = mech.contacts[0]
        return lp, _Sliding(model, support.touching.ids[k], support.touching.centres[k],
                            positions[-1], heights[-1])

    if sliding[0]:
        limit, grain = reach(0, 0.0, T[0])
    for i in range(len(T) - 1):
        dT = T[i + 1] - T[i]
        if not sliding[-1]:
            f1 = float(support.limit(T[i + 1], Q))
            if f1 <= tol:
                sliding.append(f1 >= -tol)
                positions.append(positions[-1].copy())
                heights.append(heights[-1])
                if sliding[-1]:
                    limit, grain = reach(i, 1.0, T[i + 1])
                continue
            s = crossing(lambda s: float(support.limit(T[i] + s * dT, Q)), 0.0, 1.0)
            limit, grain = reach(i, s, T[i] + s * dT)
            completed = False
            break
        if grain is None:        # two contacts start at once (a ridge): not followed
            completed = False
            break
        F = grain.terms(T[i], Q)
        fT = float(F.f_T @ dT)
        h = float(F.modulus)
        if fT > 0 and h <= 0:    # softening: no static solution beyond the limit curve
            completed = False
            break
        if fT <= 0 and h >= 0:   # no softening here: the contact unloads and the grain sticks
            support, grain = Support.at(model, grain.position), None
            sliding.append(False)
            positions.append(positions[-1].copy())
            heights.append(heights[-1])
            continue
        lam = fT / h
        grain.position = grain.position + lam * F.g_T
        grain.height -= lam * float(F.g_Q)
        grain.check_alone(i + 1)
        sliding.append(True)
        positions.append(grain.position.copy())
        heights.append(grain.height)
    m = len(positions)
    if grain is not None:
        final = grain.state()
    elif state is not None and limit is None:
        final = state
    else:
        final = limit.state if limit is not None else support.state(
            tuple(range(len(support.touching.ids))), heights[-1])
    return ForceControlResult(T[:m].copy(), np.array(positions), np.array(heights),
                              np.array(sliding), limit, completed, final)
