"""Compile exported user subroutines and call them the way their host does (ctypes).

Compilers: the system C compiler (``cc``/``gcc``) and ``gfortran``. Where one is missing the
tests that need it skip with the reason, except in CI (``CI=true``), where they fail.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import platform
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

C_FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", "-shared", "-fPIC"]
F_FLAGS = ["-ffixed-form", "-ffixed-line-length-72", "-Wall", "-Werror", "-fcheck=all",
           "-ffpe-trap=invalid,zero,overflow", "-shared", "-fPIC"]

#: What Abaqus's include file declares (double precision by implicit typing).
ABA_PARAM = "      IMPLICIT REAL*8(A-H,O-Z)\n      PARAMETER (NPRECD=2)\n"
VABA_PARAM = "      IMPLICIT REAL*8(A-H,O-Z)\n      PARAMETER (J_FLOAT_KIND=8)\n"
#: Abaqus's utility routine that ends the analysis.
XIT = ("      SUBROUTINE XIT\n      STOP 1\n      END\n"
       "      SUBROUTINE XPLB_EXIT\n      STOP 1\n      END\n")


def compiler(name: str) -> str:
    """Path of a compiler; skips (fails in CI) when there is none."""
    candidates = ("cc", "gcc") if name == "c" else ("gfortran",)
    for c in candidates:
        path = shutil.which(c)
        if path:
            return path
    msg = f"no {' or '.join(candidates)} on PATH: the compiled-export tests need it"
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(msg + " (CI=true: .ci/run installs gfortran)")
    pytest.skip(msg)


def compile_c(folder: Path, source: str) -> ctypes.CDLL:
    lib = folder / (Path(source).stem + ".so")
    cmd = [compiler("c"), *C_FLAGS, "-o", str(lib), str(folder / source), "-lm"]
    out = subprocess.run(cmd, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return ctypes.CDLL(str(lib.resolve()))


def compile_fortran(folder: Path, source: str) -> ctypes.CDLL:
    (folder / "ABA_PARAM.INC").write_text(ABA_PARAM)
    (folder / "vaba_param.inc").write_text(VABA_PARAM)
    (folder / "xit.f").write_text(XIT)
    lib = folder / (Path(source).stem + ".so")
    cmd = [compiler("fortran"), *F_FLAGS, "-I", str(folder), "-o", str(lib),
           str(folder / source), str(folder / "xit.f")]
    out = subprocess.run(cmd, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return ctypes.CDLL(str(lib.resolve()))


@contextlib.contextmanager
def fpe_traps():
    """Floating-point traps on invalid, zero-divide and overflow around the calls (glibc on
    x86-64: what ``-ffpe-trap`` sets in a Fortran main program); a no-op elsewhere."""
    libm = None
    if platform.system() == "Linux" and platform.machine() in ("x86_64", "AMD64"):
        with contextlib.suppress(OSError):
            libm = ctypes.CDLL("libm.so.6")
    flags = 0x01 | 0x04 | 0x08  # FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW
    if libm is not None:
        libm.feclearexcept(0x3D)
        libm.feenableexcept(flags)
    try:
        yield
    finally:
        if libm is not None:
            libm.fedisableexcept(flags)
            libm.feclearexcept(0x3D)


def _d(x):
    return np.ascontiguousarray(x, dtype=np.float64)


def _p(a):
    return a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))


def _i(v):
    return ctypes.byref(ctypes.c_int(int(v)))


class CKernel:
    """``<name>_update`` of the ``c`` target."""

    def __init__(self, lib, name: str, nstate: int):
        self.fun = getattr(lib, f"{name}_update")
        self.fun.restype = ctypes.c_int
        self.init = getattr(lib, f"{name}_initial_state")
        self.nstate = nstate

    def initial_state(self):
        s = np.zeros(self.nstate)
        self.init(_p(s))
        return s

    def update(self, params, state, du, tangent=True):
        params, state, du = _d(params), _d(state), _d(du)
        out, force, tan = np.zeros(self.nstate), np.zeros(3), np.zeros(9)
        rc = self.fun(_p(params), _p(state), _p(du), _p(out), _p(force),
                      _p(tan) if tangent else None)
        return rc, out, force, tan.reshape(3, 3)


class Fric:
    """Abaqus/Standard's calls of FRIC: every argument by reference, the three CHARACTER*80
    lengths appended (gfortran's convention)."""

    def __init__(self, lib):
        self.fun = lib.fric_
        self.fun.restype = None

    def call(self, lm, tau, statev, dgam, press, dpress, props, nfdir):
        """One call; returns ``(lm, tau, ddtddg, ddtddp, dslip, sed, sfd, pnewdt, statev)``."""
        n = nfdir
        tau, statev, dgam, props = _d(tau).copy(), _d(statev).copy(), _d(dgam), _d(props)
        lm_c = ctypes.c_int(lm)
        ddtddg, ddtddp, dslip = np.zeros((n, n), order="F"), np.zeros(n), np.zeros(n)
        ddtddt, taulm, slip = np.zeros((n, 2), order="F"), np.zeros(n), np.zeros(n)
        sed, sfd, pnewdt = ctypes.c_double(0), ctypes.c_double(0), ctypes.c_double(1.0)
        time, coords, rcoords = np.zeros(2), np.zeros(3), np.zeros(3)
        drot, temp, predef = np.eye(2, order="F"), np.zeros(2), np.zeros((2, 1), order="F")
        name = ctypes.create_string_buffer(b" " * 80, 80)
        d = ctypes.byref
        self.fun(d(lm_c), _p(tau), _p(ddtddg), _p(ddtddp), _p(dslip), d(sed), d(sfd),
                 _p(ddtddt), d(pnewdt), _p(statev), _p(dgam), _p(taulm),
                 d(ctypes.c_double(press)), d(ctypes.c_double(dpress)), d(ctypes.c_double(0)),
                 _p(slip), _i(1), _i(1), _p(time), d(ctypes.c_double(1.0)), _i(1), name, name,
                 name, _i(1), _i(1), _i(1), _p(coords), _p(rcoords), _p(drot), _p(temp),
                 _p(predef), _i(n), _i(3), _i(0), _i(len(statev)), d(ctypes.c_double(1.0)),
                 _p(props), _i(len(props)), ctypes.c_size_t(80), ctypes.c_size_t(80),
                 ctypes.c_size_t(80))
        return (lm_c.value, tau, ddtddg, ddtddp, dslip, sed.value, sfd.value, pnewdt.value,
                statev)


class Uinter:
    """Abaqus/Standard's call of UINTER (every argument by reference, CHARACTER lengths last)."""

    def __init__(self, lib):
        self.fun = lib.uinter_
        self.fun.restype = None

    def call(self, statev, rdisp, drdisp, props, ndir, lopenclose=1):
        """One call; returns ``(stress, ddsddr, statev, sed, sfd, spd, pnewdt, lstate, lsdi)``."""
        n = ndir
        statev, rdisp, drdisp, props = (_d(statev).copy(), _d(rdisp), _d(drdisp), _d(props))
        stress, ddsddr = np.zeros(n), np.zeros((n, n), order="F")
        flux, ddfddt = np.zeros(2), np.zeros((2, 2), order="F")
        ddsddt, ddfddr = np.zeros((n, 2), order="F"), np.zeros((2, n), order="F")
        sed, sfd, spd, svd, scd = (ctypes.c_double(0) for _ in range(5))
        pnewdt = ctypes.c_double(1.0)
        temp, dtemp, time = np.zeros(2), np.zeros(2), np.zeros(2)
        predef, dpred = np.zeros((2, 1), order="F"), np.zeros((2, 1), order="F")
        coords, alocal, drot = np.zeros(3), np.eye(3, order="F"), np.eye(2, order="F")
        lstate, lsdi = ctypes.c_int(0), ctypes.c_int(0)
        name = ctypes.create_string_buffer(b" " * 80, 80)
        d = ctypes.byref
        amki, amski = np.zeros((n, n), order="F"), np.zeros((n, n), order="F")
        self.fun(_p(stress), _p(ddsddr), _p(amki), _p(amski), _p(flux), _p(ddfddt),
                 _p(ddsddt), _p(ddfddr),
                 _p(statev), d(sed), d(sfd), d(spd), d(svd), d(scd), d(pnewdt), _p(rdisp),
                 _p(drdisp), _p(temp), _p(dtemp), _p(predef), _p(dpred), _p(time),
                 d(ctypes.c_double(1.0)), d(ctypes.c_double(0.0)), name, name, name,
                 _p(props), _p(coords), _p(alocal), _p(drot), d(ctypes.c_double(1.0)),
                 d(ctypes.c_double(1.0)), _i(1), _i(n), _i(len(statev)), _i(1),
                 _i(len(props)), _i(3), _i(1), _i(1), _i(0), _i(0), _i(lopenclose),
                 d(lstate), d(lsdi), _i(0), ctypes.c_size_t(80), ctypes.c_size_t(80),
                 ctypes.c_size_t(80))
        return (stress, ddsddr, statev, sed.value, sfd.value, spd.value, pnewdt.value,
                lstate.value, lsdi.value)


class Vfric:
    """Abaqus/Explicit's call of VFRIC for ``n`` contact points, one per slave node
    (``jConSlvid`` = 1 … n), the CHARACTER*8 lengths appended."""

    def __init__(self, lib):
        self.fun = lib.vfric_
        self.fun.restype = None

    def call(self, state, props, dslip, fstick, fnormal, dircos_n, dircos_sl, nfricdir):
        """``state`` (nstatevar, n); vectors (ndir, n); returns ``(f_tangential, state)``."""
        ndir, n = np.shape(dircos_n)
        state = np.array(state, dtype=float).reshape(-1, n)
        if state.size == 0:
            state = np.zeros((1, n))
        state = np.asfortranarray(state)
        f = np.zeros((nfricdir, n), order="F")
        F = np.asfortranarray
        dslip, dn, dsl = F(_d(dslip)), F(_d(dircos_n)), F(_d(dircos_sl))
        fstick, fnormal, props = _d(fstick), _d(fnormal), _d(props)
        ints = np.arange(1, n + 1, dtype=np.int32)
        zeros = np.zeros((3, 4 * n + 4), order="F")
        name = ctypes.create_string_buffer(b" " * 8, 8)
        ip = lambda a: a.ctypes.data_as(ctypes.POINTER(ctypes.c_int))  # noqa: E731
        r = lambda v: ctypes.byref(ctypes.c_double(v))  # noqa: E731
        self.fun(_p(f), _p(state), _i(1), _i(1), _i(n), _i(4), _i(n), _i(4), _i(nfricdir),
                 _i(ndir), _i(state.shape[0]), _i(len(props)), _i(0), _i(1), _i(1),
                 ip(ints), ip(ints), ip(ints), ip(np.ones(4 * n, dtype=np.int32)), r(1e-6),
                 r(1e-3), r(1e-6), name, name, name, _i(1), _p(dslip), _p(fstick),
                 _p(np.zeros((ndir, n), order="F")), _p(fnormal), r(0.0), _p(zeros), _p(zeros),
                 _p(zeros), _p(dsl), _p(dn), _p(props), _p(np.ones(n)), _p(np.zeros(n)),
                 _p(zeros), _p(zeros), _p(zeros), ctypes.c_size_t(8), ctypes.c_size_t(8),
                 ctypes.c_size_t(8))
        return f, state
