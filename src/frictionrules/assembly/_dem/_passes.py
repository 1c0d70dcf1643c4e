r"""The two compiled passes of a time step: contacts (kinematics and the law) and grains (forces,
damping, leapfrog).

**Contact kinematics** (pair ``i, j``, image ``K``, branch ``l = x_j + H K - x_i``, gap
``|l| - r_i - r_j``, normal ``n = l/|l|`` from ``i`` to ``j``, frame ``t1`` the unit projection of
the reference axis on the contact plane, ``t2 = n × t1`` as :func:`..._contacts.frames`):

* a pair out of contact touches (gap ≤ 0): a virgin contact (zero displacements, the law's
  initial internal variables) takes the normal increment ``Δδn = gap``;
* a contact opens beyond the skin (gap > s): it is deleted;
* otherwise its history is carried into the new frame — the tangential elastic and plastic
  displacements, as vectors of the old contact plane, turned by the rotation taking the old
  normal to the new one, then about ``n`` by the mean spin ``dt (ω_i + ω_j)·n / 2`` (YADE's
  ``ScGeom::rotate``, here exact rotations; the turn of the frame is one plane rotation of
  both, :func:`_turn`) — and the increment is
  ``Δδt = dt Q_t (v'_j - v'_i + L l - (r_i ω_i + r_j ω_j) × n)``, ``Δδn = gap - gap_old``
  (the normal displacement follows the geometry: no drift of N);
* the law's compiled update (:func:`frictionrules.contact.contact_update`) gives the force
  ``(T1, T2, N)``; the force of ``j`` on ``i`` is ``g = T1 t1 + T2 t2 - N n`` and the moment
  on either grain its radius times ``n × g``.

During a frictionless stage the law is ``Coulomb(0)``, whose return takes any tangential trial
force to zero: the contact keeps its tangential history (zero from its first touch) and gets
the normal response alone, ``g = -N n``, the same result without the return at the degenerate
cone's axis, without the frame and without the tangential kinematics (4,000 spheres
consolidated in 48k steps: 58 s -> 28 s on 2 threads). Its stored frame goes stale: the laws'
stage starts every tangential history at zero (:meth:`._dynamics.Dynamics.bring_in_laws`),
which a stale frame carries as zero, and records take their frames from the normals
(:func:`frame_t1`).

The pass is bound by the latency of each contact's chain of dependent operations, not by its
memory (``benchmarks/dem_pass_floor.py``): what can start from the branch ``l`` does — the
frame's square root beside the normal's, the turn's quotient and the twist — and the frame
turns once for both histories (10,800 spheres, one thread: 2.51 -> 2.01 ms a pass).

Each chunk of pairs adds to its row of partial sums (named columns ``P_*``): the virial, the
laws' dissipation, ``Σ|g|`` and the counts of force-carrying and sliding contacts, the largest
overlap, the affine stiffness of each cell component (the servo's), the first failed pair.

**Grain pass** (YADE's ``NewtonIntegrator``): the forces and moments gathered from the grain's
pairs; Cundall's non-viscous damping of each component, ``a ← a (1 - λ sgn(F (v + a dt/2)))``;
leapfrog ``v ← v + a dt``, ``x ← x + dt (v + L x)`` (``v`` the fluctuation velocity, ``L`` the
cell's velocity gradient of the step), spins alike (no orientation is needed for round grains).
Each chunk of grains adds ``Σ|F|``, the kinetic energy of the new half step, the work lost to
damping (``-F_d·(v_old + v_new)/2 dt``) and the largest displacement since the neighbour build
apart from the affine one.
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from ...contact import contact_update
from ...contact.layout import LAW_KN, LAW_KT, RES_DISSIPATION, RES_FORCE, RES_SLIP
from ._state import ELASTIC, OPEN, PLASTIC

__all__ = ["contact_range", "grain_range", "frame_t1", "P_VIRIAL", "P_DISSIPATION", "P_FORCE",
           "P_CLOSED", "P_SLIDING", "P_OVERLAP", "P_STIFF", "P_FAILED", "P_SIZE", "G_FORCE",
           "G_KINETIC", "G_DAMPING", "G_SHIFT", "G_SIZE", "MAX_DEPTH", "gather_range",
           "fire_range", "F_POWER", "F_FORCE2", "F_SPEED2", "F_FORCE"]

#: The passes' one relaxation of IEEE arithmetic: a product and a sum may be fused into one
#: multiply-add (one rounding instead of two). Nothing else (no reassociation, no finite-math
#: assumptions: the checks for NaN and infinity stay); 400 spheres: 139 -> 126 µs per step.
_FMA = {"contract"}

#: Substeps of a contact update whose Newton iteration fails: up to 2**MAX_DEPTH.
MAX_DEPTH = 10
#: The contact pass asks the cache for the grain ``j`` of the pair this many pairs ahead (its
#: position, velocity and spin: a pair's second grain is anywhere in the grain arrays, and one
#: contact's work is too long for the processor to reach the next one's loads by itself).
#: 10,800 spheres, the least of 600 passes: 2.93 -> 2.72 ms (8 ahead; 16 the same, 4: 2.78 ->
#: 2.72); 137,200 spheres: 77 -> 71 ms.
AHEAD = 8

#: Columns of a contact chunk's partial sums: the virial Σ f⊗l (9, row-major), the laws'
#: dissipation, Σ|g| over force-carrying contacts, their count, the sliding ones, the largest
#: overlap over the smaller radius, the affine stiffness of the 6 cell components, the first
#: failed pair (-1 none).
P_VIRIAL, P_DISSIPATION, P_FORCE, P_CLOSED, P_SLIDING, P_OVERLAP, P_STIFF, P_FAILED = 0, 9, 10, 11, 12, 13, 14, 20
P_SIZE = 21
#: Columns of a grain chunk's partial sums: Σ|F|, kinetic energy, damping loss, largest
#: non-affine displacement since the neighbour build.
G_FORCE, G_KINETIC, G_DAMPING, G_SHIFT = 0, 1, 2, 3
G_SIZE = 4


@intrinsic
def _prefetch(typingctx, arr, row):
    """Ask the cache for row ``row`` of the 2-d array ``arr`` (LLVM's ``prefetch``, for reading,
    to every level): no effect on any value."""
    sig = types.void(arr, row)

    def codegen(context, builder, signature, args):
        aryty = signature.args[0]
        ary = context.make_array(aryty)(context, builder, args[0])
        zero = ir.Constant(ir.IntType(64), 0)
        ptr = cgutils.get_item_pointer(context, builder, aryty, ary, [args[1], zero])
        byte, i32 = ir.IntType(8).as_pointer(), ir.IntType(32)
        fn = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [byte, i32, i32, i32]),
            "llvm.prefetch.p0i8")
        builder.call(fn, [builder.bitcast(ptr, byte), ir.Constant(i32, 0), ir.Constant(i32, 3),
                          ir.Constant(i32, 1)])
        return context.get_dummy_value()

    return sig, codegen


@njit(inline="always", error_model="numpy", fastmath=_FMA)
def _frame(lx, ly, lz, d2, d, ax, ay, az):
    """t1 of :func:`frictionrules.assembly._contacts.frames` for the normal ``n = l/d``
    (``d2 = |l|²``, ``d = √d2``): the unit projection of the (unit) reference axis ``a`` on the
    contact plane, ``(a - (a·n) n)/√(1 - (a·n)²)``, written with the branch ``l`` itself,
    ``(d2 a - (a·l) l) / (d |l × a|)``: its square root does not wait for the normal's (the two
    run side by side), and ``|l × a|² = d2 - (a·l)²`` summed from the cross product has no
    cancellation (``t1`` is unit to a few eps over the sine of the angle between ``a`` and
    ``n``); where ``a`` is normal to the contact (``|l × a|² < 1e-12 d2``), of the next global
    axis."""
    al = ax * lx + ay * ly + az * lz
    cx, cy, cz = ly * az - lz * ay, lz * ax - lx * az, lx * ay - ly * ax
    q = cx * cx + cy * cy + cz * cz
    if q < 1e-12 * d2:
        bx, by, bz = abs(ax), abs(ay), abs(az)
        if bx >= by and bx >= bz:
            ax, ay, az = 0.0, 1.0, 0.0
        elif by >= bz:
            ax, ay, az = 0.0, 0.0, 1.0
        else:
            ax, ay, az = 1.0, 0.0, 0.0
        al = ax * lx + ay * ly + az * lz
        cx, cy, cz = ly * az - lz * ay, lz * ax - lx * az, lx * ay - ly * ax
        q = cx * cx + cy * cy + cz * cz
    inv = 1.0 / (d * math.sqrt(q))
    return (d2 * ax - al * lx) * inv, (d2 * ay - al * ly) * inv, (d2 * az - al * lz) * inv


@njit(cache=True, error_model="numpy", fastmath=_FMA)
def frame_t1(normal, ax, ay, az):
    """The frame vector ``t1`` (m, 3) of the contacts of unit normals ``normal`` (m, 3): the
    rule of the contact pass (:func:`_frame`), for the records whatever the stage (a
    frictionless stage does not keep its frames)."""
    m = normal.shape[0]
    t1 = np.empty((m, 3))
    for k in range(m):
        nx, ny, nz = normal[k, 0], normal[k, 1], normal[k, 2]
        d2 = nx * nx + ny * ny + nz * nz
        t1[k, 0], t1[k, 1], t1[k, 2] = _frame(nx, ny, nz, d2, math.sqrt(d2), ax, ay, az)
    return t1


@njit(inline="always", error_model="numpy", fastmath=_FMA)
def _turn(n0x, n0y, n0z, a0, a1, a2, lx, ly, lz, d, nx, ny, nz, t1x, t1y, t1z, t2x, t2y, t2z, ct,
          st):
    """``(cos φ, sin φ)`` of the turn of the old frame ``(t1_old, n_old × t1_old)`` (``a`` =
    ``t1_old``) into the new one ``(t1, t2)``: ``t1_old`` carried with the contact (the rotation
    taking ``n_old`` to ``n = l/d`` about their common perpendicular, ``v - (n·v)/(1 +
    n_old·n) (n_old + n)``, its quotient written with the branch ``l``, ``(l·v)/(d +
    n_old·l)``, so that it does not wait for ``n``), then about ``n`` by the twist ``(cos,
    sin)``, in the new frame. The turn is a proper rotation: it takes ``n_old × t1_old`` to
    ``n ×`` the turned ``t1_old``, so a tangential vector ``(u1, u2)`` of the old frame is
    ``(cos φ u1 - sin φ u2, sin φ u1 + cos φ u2)`` in the new (:func:`_rotate`): one turn of
    the frame serves the elastic and the plastic displacements."""
    c = (lx * a0 + ly * a1 + lz * a2) / (d + n0x * lx + n0y * ly + n0z * lz)
    vx, vy, vz = a0 - c * (n0x + nx), a1 - c * (n0y + ny), a2 - c * (n0z + nz)
    ca = vx * t1x + vy * t1y + vz * t1z
    sa = vx * t2x + vy * t2y + vz * t2z
    return ca * ct - sa * st, sa * ct + ca * st


@njit(inline="always", error_model="numpy", fastmath=_FMA)
def _rotate(u1, u2, cp, sp):
    """The tangential vector ``(u1, u2)`` of the old frame in the new (:func:`_turn`)."""
    return cp * u1 - sp * u2, sp * u1 + cp * u2


@njit(inline="always", error_model="numpy", fastmath=_FMA)
def _normal_only(kn, s, dun, s1, res, width):
    """A frictionless contact: the normal elastic response alone, ``N = -kn e_n`` while
    ``e_n = e_n + Δδn < 0``, no tangential force and no tangential history (the update of
    :func:`frictionrules.contact.contact_update` with μ = 0, without a return at the cone's
    axis). Returns the status."""
    for a in range(width):
        s1[a] = s[a]
    en = s[2] + dun
    s1[2] = en
    res[RES_FORCE] = 0.0
    res[RES_FORCE + 1] = 0.0
    res[RES_FORCE + 2] = -kn * en if en < 0.0 else 0.0
    res[RES_DISSIPATION] = 0.0
    res[RES_SLIP] = 0.0
    return ELASTIC if en < 0.0 else OPEN


@njit(error_model="numpy", _nrt=False, cache=True, fastmath=_FMA)
def contact_range(lo, hi, fn, row, virgin, ws, lists, grains, cell, pairs, params, scratch, part):
    """Pairs ``order[lo:hi]`` (all of one contact model: ``fn``, ``row``, ``virgin``; ``ws``
    the workspace of its ``nq``). ``scratch = (s, du, res, tan)``; ``part`` the chunk's row."""
    order = lists.order
    x, v, w, R = grains.x, grains.v, grains.w, grains.radius
    H, L = cell.H, cell.L
    dt, skin, frictionless = params.dt, params.skin, params.frictionless
    ax, ay, az = params.axis0, params.axis1, params.axis2
    s, du, res, tan = scratch
    W = s.shape[0]
    kt, kn = row[LAW_KT], row[LAW_KN]
    PI, PJ, PK = pairs.i, pairs.j, pairs.shift
    ACT, S, NRM, T1, GAP = pairs.active, pairs.state, pairs.normal, pairs.t1, pairs.gap
    FRC, GF, TQ, ST, SLIP = pairs.force, pairs.gforce, pairs.torque, pairs.status, pairs.slip
    v00 = v01 = v02 = v10 = v11 = v12 = v20 = v21 = v22 = 0.0
    s0 = s1 = s2 = s3 = s4 = s5 = 0.0
    diss = fsum = closed = sliding = over = 0.0
    bad = -1
    for k in range(lo, hi):
        if k + AHEAD < hi:
            ahead = PJ[order[k + AHEAD]]
            _prefetch(x, ahead)
            _prefetch(v, ahead)
            _prefetch(w, ahead)
        c = order[k]
        i, j = PI[c], PJ[c]
        k0, k1, k2 = PK[c, 0], PK[c, 1], PK[c, 2]
        lx = x[j, 0] - x[i, 0] + H[0, 0] * k0 + H[0, 1] * k1 + H[0, 2] * k2
        ly = x[j, 1] - x[i, 1] + H[1, 0] * k0 + H[1, 1] * k1 + H[1, 2] * k2
        lz = x[j, 2] - x[i, 2] + H[2, 0] * k0 + H[2, 1] * k1 + H[2, 2] * k2
        d2 = lx * lx + ly * ly + lz * lz
        dist = math.sqrt(d2)
        ri, rj = R[i], R[j]
        gap = dist - ri - rj
        fresh = ACT[c] == 0
        if fresh and gap > 0.0:
            continue
        if gap > skin:  # opened beyond the skin: the contact is deleted
            ACT[c] = 0
            ST[c] = OPEN
            for a in range(3):
                FRC[c, a] = 0.0
                GF[c, a] = 0.0
                TQ[c, a] = 0.0
            continue
        inv = 1.0 / dist
        nx, ny, nz = lx * inv, ly * inv, lz * inv
        if fresh:
            ACT[c] = 1
            SLIP[c] = 0.0
            for a in range(W):
                s[a] = virgin[a]
        if frictionless:
            # the normal response alone: no frame and no tangential kinematics (the stored frame
            # goes stale: the laws' stage starts every tangential history at zero, and a record
            # takes its frames from the normals)
            t1x = t1y = t1z = t2x = t2y = t2z = 0.0
            if fresh:
                status = _normal_only(kn, s, gap, S[c], res, W)
            else:
                status = _normal_only(kn, S[c], gap - GAP[c], S[c], res, W)
            failed = False
        else:
            t1x, t1y, t1z = _frame(lx, ly, lz, d2, dist, ax, ay, az)
            t2x, t2y, t2z = ny * t1z - nz * t1y, nz * t1x - nx * t1z, nx * t1y - ny * t1x
            if fresh:
                du[0] = 0.0
                du[1] = 0.0
                du[2] = gap
            else:
                # the twist: an exact rotation by 2 atan(h), h = tan(θ/2) to O(θ⁵), θ = dt (ω_i
                # + ω_j)·n / 2 (with l, then 1/|l|: it does not wait for n)
                h = 0.25 * dt * ((w[i, 0] + w[j, 0]) * lx + (w[i, 1] + w[j, 1]) * ly
                                 + (w[i, 2] + w[j, 2]) * lz) * inv
                h += h * h * h / 3.0
                h2 = 1.0 / (1.0 + h * h)
                cp, sp = _turn(NRM[c, 0], NRM[c, 1], NRM[c, 2], T1[c, 0], T1[c, 1], T1[c, 2],
                               lx, ly, lz, dist, nx, ny, nz, t1x, t1y, t1z, t2x, t2y, t2z,
                               (1.0 - h * h) * h2, 2.0 * h * h2)
                row_c = S[c]
                s[0], s[1] = _rotate(row_c[0], row_c[1], cp, sp)
                s[3], s[4] = _rotate(row_c[3], row_c[4], cp, sp)
                s[2] = row_c[2]
                for a in range(5, W):
                    s[a] = row_c[a]
                # relative velocity of j's contact point to i's
                ox = ri * w[i, 0] + rj * w[j, 0]
                oy = ri * w[i, 1] + rj * w[j, 1]
                oz = ri * w[i, 2] + rj * w[j, 2]
                ux = (v[j, 0] - v[i, 0] + L[0, 0] * lx + L[0, 1] * ly + L[0, 2] * lz
                      - (oy * nz - oz * ny))
                uy = (v[j, 1] - v[i, 1] + L[1, 0] * lx + L[1, 1] * ly + L[1, 2] * lz
                      - (oz * nx - ox * nz))
                uz = (v[j, 2] - v[i, 2] + L[2, 0] * lx + L[2, 1] * ly + L[2, 2] * lz
                      - (ox * ny - oy * nx))
                du[0] = dt * (ux * t1x + uy * t1y + uz * t1z)
                du[1] = dt * (ux * t2x + uy * t2y + uz * t2z)
                du[2] = gap - GAP[c]
            status, failed = contact_update(fn, row, s, du, S[c], res, ws, MAX_DEPTH, False, tan)
        if failed and (bad < 0 or c < bad):
            bad = c
        T1f, T2f, Nf = res[RES_FORCE], res[RES_FORCE + 1], res[RES_FORCE + 2]
        gx = T1f * t1x + T2f * t2x - Nf * nx
        gy = T1f * t1y + T2f * t2y - Nf * ny
        gz = T1f * t1z + T2f * t2z - Nf * nz
        FRC[c, 0], FRC[c, 1], FRC[c, 2] = T1f, T2f, Nf
        GF[c, 0], GF[c, 1], GF[c, 2] = gx, gy, gz
        TQ[c, 0], TQ[c, 1], TQ[c, 2] = ny * gz - nz * gy, nz * gx - nx * gz, nx * gy - ny * gx
        NRM[c, 0], NRM[c, 1], NRM[c, 2] = nx, ny, nz
        if not frictionless:
            T1[c, 0], T1[c, 1], T1[c, 2] = t1x, t1y, t1z
        GAP[c] = gap
        ST[c] = status
        SLIP[c] += res[RES_SLIP]
        diss += res[RES_DISSIPATION]
        if gap < 0.0:
            over = max(over, -gap / min(ri, rj))
        if Nf > 0.0:
            # the virial of f = -g (the force of i on j): compression positive
            v00 -= gx * lx
            v01 -= gx * ly
            v02 -= gx * lz
            v10 -= gy * lx
            v11 -= gy * ly
            v12 -= gy * lz
            v20 -= gz * lx
            v21 -= gz * ly
            v22 -= gz * lz
            fsum += math.sqrt(gx * gx + gy * gy + gz * gz)
            closed += 1.0
            if status == PLASTIC:
                sliding += 1.0
            # affine stiffness (K_c G_k l)_a l_b, K_c = kt I + (kn - kt) n n
            dk = kn - kt
            s0 += (kt + dk * nx * nx) * lx * lx
            s1 += (kt + dk * ny * ny) * ly * ly
            s2 += (kt + dk * nz * nz) * lz * lz
            s3 += ((kt + dk * ny * ny) * lz + dk * ny * nz * ly) * lz
            s4 += ((kt + dk * nx * nx) * lz + dk * nx * nz * lx) * lz
            s5 += ((kt + dk * nx * nx) * ly + dk * nx * ny * lx) * ly
    part[P_VIRIAL + 0] += v00
    part[P_VIRIAL + 1] += v01
    part[P_VIRIAL + 2] += v02
    part[P_VIRIAL + 3] += v10
    part[P_VIRIAL + 4] += v11
    part[P_VIRIAL + 5] += v12
    part[P_VIRIAL + 6] += v20
    part[P_VIRIAL + 7] += v21
    part[P_VIRIAL + 8] += v22
    part[P_DISSIPATION] += diss
    part[P_FORCE] += fsum
    part[P_CLOSED] += closed
    part[P_SLIDING] += sliding
    part[P_OVERLAP] = max(part[P_OVERLAP], over)
    part[P_STIFF + 0] += s0
    part[P_STIFF + 1] += s1
    part[P_STIFF + 2] += s2
    part[P_STIFF + 3] += s3
    part[P_STIFF + 4] += s4
    part[P_STIFF + 5] += s5
    if bad >= 0 and (part[P_FAILED] < 0.0 or bad < part[P_FAILED]):
        part[P_FAILED] = bad


@njit(inline="always", error_model="numpy", fastmath=_FMA)
def _damped_step(F, old, inv, dt, lam):
    """One component of the leapfrog with Cundall's damping: the new velocity (or spin) under
    the force (or moment) ``F`` and inverse mass (or moment of inertia) ``inv``, the work lost
    to damping and twice the kinetic energy of the new half step."""
    acc = F * inv
    damp = lam * math.copysign(1.0, F * (old + 0.5 * dt * acc)) if F != 0.0 else 0.0
    new = old + dt * acc * (1.0 - damp)
    return new, damp * F * 0.5 * (old + new) * dt, new * new / inv


@njit(inline="always", error_model="numpy", fastmath=_FMA)
def _gather(g, start, entry, GF, TQ, moments):
    """The force on grain ``g`` from its pairs, and the sum of their ``n × g`` (``moments``)."""
    f0 = f1 = f2 = 0.0
    m0 = m1 = m2 = 0.0
    for e in range(start[g], start[g + 1]):
        code = entry[e]
        c = code >> 1
        if code & 1:
            f0 -= GF[c, 0]
            f1 -= GF[c, 1]
            f2 -= GF[c, 2]
        else:
            f0 += GF[c, 0]
            f1 += GF[c, 1]
            f2 += GF[c, 2]
        if moments:
            m0 += TQ[c, 0]
            m1 += TQ[c, 1]
            m2 += TQ[c, 2]
    return f0, f1, f2, m0, m1, m2


@njit(inline="always", error_model="numpy", fastmath=_FMA)
def _move(g, x, v, L, dt, F_build, xb):
    """``x ← x + dt (v + L x)`` of grain ``g``; the square of its displacement since the
    neighbour build apart from the affine one."""
    x0, x1, x2 = x[g, 0], x[g, 1], x[g, 2]
    x[g, 0] = x0 + dt * (v[g, 0] + L[0, 0] * x0 + L[0, 1] * x1 + L[0, 2] * x2)
    x[g, 1] = x1 + dt * (v[g, 1] + L[1, 0] * x0 + L[1, 1] * x1 + L[1, 2] * x2)
    x[g, 2] = x2 + dt * (v[g, 2] + L[2, 0] * x0 + L[2, 1] * x1 + L[2, 2] * x2)
    d0 = x[g, 0] - (F_build[0, 0] * xb[g, 0] + F_build[0, 1] * xb[g, 1] + F_build[0, 2] * xb[g, 2])
    d1 = x[g, 1] - (F_build[1, 0] * xb[g, 0] + F_build[1, 1] * xb[g, 1] + F_build[1, 2] * xb[g, 2])
    d2 = x[g, 2] - (F_build[2, 0] * xb[g, 0] + F_build[2, 1] * xb[g, 1] + F_build[2, 2] * xb[g, 2])
    return d0 * d0 + d1 * d1 + d2 * d2


@njit(error_model="numpy", _nrt=False, cache=True, fastmath=_FMA)
def grain_range(lo, hi, lists, grains, cell, pairs, params, F_build, part):
    """Grains ``lo <= g < hi``: gather, damp, integrate. ``F_build = H_new H_build^{-1}`` for
    the displacement since the neighbour build; ``part`` the chunk's row."""
    start, entry = lists.grain_start, lists.grain_entry
    x, v, w, R = grains.x, grains.v, grains.w, grains.radius
    im, ii, xb = grains.inv_mass, grains.inv_inertia, grains.x_build
    L = cell.L
    GF, TQ = pairs.gforce, pairs.torque
    dt, lam = params.dt, params.damping
    fsum = kinetic = damping = largest = 0.0
    for g in range(lo, hi):
        f0, f1, f2, m0, m1, m2 = _gather(g, start, entry, GF, TQ, True)
        r = R[g]
        m0, m1, m2 = r * m0, r * m1, r * m2
        fsum += math.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
        kin = 0.0
        loss = 0.0
        for a in range(3):
            v[g, a], lost, k = _damped_step(f0 if a == 0 else (f1 if a == 1 else f2), v[g, a],
                                            im[g], dt, lam)
            loss += lost
            kin += k
            w[g, a], lost, k = _damped_step(m0 if a == 0 else (m1 if a == 1 else m2), w[g, a],
                                            ii[g], dt, lam)
            loss += lost
            kin += k
        kinetic += 0.5 * kin
        damping += loss
        largest = max(largest, _move(g, x, v, L, dt, F_build, xb))
    part[G_FORCE] += fsum
    part[G_KINETIC] += kinetic
    part[G_DAMPING] += damping
    part[G_SHIFT] = max(part[G_SHIFT], math.sqrt(largest))


#: Columns of a grain chunk's partial sums in a FIRE step's first pass: ``F·v``, ``|F|²``,
#: ``|v|²``, ``Σ|F|``.
F_POWER, F_FORCE2, F_SPEED2, F_FORCE = 0, 1, 2, 3


@njit(error_model="numpy", _nrt=False, cache=True, fastmath=_FMA)
def gather_range(lo, hi, lists, grains, pairs, force, part):
    """Grains ``lo <= g < hi``: the force on each from its pairs into ``force`` (a frictionless
    stage: no moments), and the chunk's ``F·v``, ``|F|²``, ``|v|²`` and ``Σ|F|``."""
    start, entry = lists.grain_start, lists.grain_entry
    v = grains.v
    GF = pairs.gforce
    power = f2 = v2 = fsum = 0.0
    for g in range(lo, hi):
        f0, f1, f2g, _, _, _ = _gather(g, start, entry, GF, GF, False)
        force[g, 0], force[g, 1], force[g, 2] = f0, f1, f2g
        power += f0 * v[g, 0] + f1 * v[g, 1] + f2g * v[g, 2]
        ff = f0 * f0 + f1 * f1 + f2g * f2g
        f2 += ff
        v2 += v[g, 0] * v[g, 0] + v[g, 1] * v[g, 1] + v[g, 2] * v[g, 2]
        fsum += math.sqrt(ff)
    part[F_POWER] += power
    part[F_FORCE2] += f2
    part[F_SPEED2] += v2
    part[F_FORCE] += fsum


@njit(error_model="numpy", _nrt=False, cache=True, fastmath=_FMA)
def fire_range(lo, hi, grains, cell, force, dt, keep, mix, F_build, part):
    """Grains ``lo <= g < hi``: FIRE's velocity ``v ← keep ((1 - α) v) + mix F`` (``keep``
    the factor ``1 - α``, or 0 after an uphill step; ``mix = α |v|/|F|``), then the
    semi-implicit Euler step ``v ← v + dt F/m``, ``x ← x + dt (v + L x)``; spins stay zero. The
    chunk's kinetic energy and largest non-affine displacement since the neighbour build."""
    x, v, w, im, xb = grains.x, grains.v, grains.w, grains.inv_mass, grains.x_build
    L = cell.L
    kinetic = largest = 0.0
    for g in range(lo, hi):
        for a in range(3):
            f = force[g, a]
            v[g, a] = keep * v[g, a] + mix * f + dt * f * im[g]
            w[g, a] = 0.0
        kinetic += 0.5 * (v[g, 0] ** 2 + v[g, 1] ** 2 + v[g, 2] ** 2) / im[g]
        largest = max(largest, _move(g, x, v, L, dt, F_build, xb))
    part[G_KINETIC] += kinetic
    part[G_SHIFT] = max(part[G_SHIFT], math.sqrt(largest))
