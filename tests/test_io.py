"""FCLIB HDF5 reading and writing: layouts (triplet, CSC, CSR), condensation, bad files."""

from __future__ import annotations

import os
from pathlib import Path

import h5py
import numpy as np
import pytest
import scipy.sparse as sp

import frictionrules
from frictionrules import FrictionContactProblem, FrictionRulesError, read_fclib, solve, write_fclib
from frictionrules.io import GlobalProblem, read_fclib_global, write_fclib_global


def fclib_dir() -> Path:
    """The shared FCLIB folder: ``<repo>/../shared/fclib`` or ``$FRICTIONRULES_FCLIB``."""
    here = Path(__file__).resolve().parents[2] / "shared" / "fclib"
    return here if here.is_dir() else Path(os.environ.get("FRICTIONRULES_FCLIB", here))


FCLIB = fclib_dir()
#: Skips where the shared FCLIB files are missing, except in CI (``CI=true``): there the tests
#: run and fail loudly on the missing files.
needs_fclib = pytest.mark.skipif(not FCLIB.is_dir() and os.environ.get("CI") != "true",
                                 reason=f"no FCLIB data in {FCLIB}")


def random_problem(nc=4, seed=0):
    rng = np.random.default_rng(seed)
    A = sp.random(3 * nc, 3 * nc, density=0.3, random_state=seed) + sp.identity(3 * nc)
    return FrictionContactProblem(A @ A.T, rng.normal(size=3 * nc), rng.uniform(0.1, 0.9, nc),
                                  title="random")


def test_public_names():
    assert frictionrules.io.read_fclib is read_fclib
    for name in ("FrictionContactProblem", "solve", "Solution", "read_fclib", "write_fclib"):
        assert name in frictionrules.__all__


def test_local_roundtrip(tmp_path):
    p = random_problem()
    s = solve(p)
    path = write_fclib(tmp_path / "p.hdf5", p, solution=s, description="pile de sphères")
    back = read_fclib(path)
    assert (back.W != p.W).nnz == 0
    np.testing.assert_array_equal(back.q, p.q)
    np.testing.assert_array_equal(back.mu_bar, p.mu_bar)
    assert back.title == "random"
    with h5py.File(path) as h5:
        assert int(h5["fclib_local/W/nz"][0]) == -2
        np.testing.assert_array_equal(h5["solution/r"][()], s.r)
    assert not list(tmp_path.glob(".p.hdf5*"))  # atomic: no temporary left


def global_problem(seed=1):
    rng = np.random.default_rng(seed)
    ndof, nc = 7, 2
    B = rng.normal(size=(ndof, ndof))
    M = sp.csc_matrix(B @ B.T + ndof * np.eye(ndof))
    H = sp.csc_matrix(rng.normal(size=(ndof, 3 * nc)))
    return GlobalProblem(M, H, rng.normal(size=ndof), rng.normal(size=3 * nc), np.array([0.3, 0.6]),
                         title="global")


@pytest.mark.parametrize("dense_max", [400, 0], ids=["dense", "sparse"])
def test_global_condensation_W_HtMinvH(tmp_path, monkeypatch, dense_max):
    """W = H^T M^-1 H, q = H^T M^-1 f + w, by the dense solve of a small M and by SuperLU."""
    import frictionrules.io as fio
    monkeypatch.setattr(fio, "DENSE_CONDENSE_MAX", dense_max)
    g = global_problem()
    path = write_fclib_global(tmp_path / "g.hdf5", g)
    p = read_fclib(path)
    Minv = np.linalg.inv(g.M.toarray())
    Hd = g.H.toarray()
    np.testing.assert_allclose(p.W.toarray(), Hd.T @ Minv @ Hd, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(p.q, Hd.T @ Minv @ g.f + g.w, rtol=1e-12, atol=1e-12)
    back = read_fclib_global(path)
    assert (back.M != g.M).nnz == 0 and (back.H != g.H).nnz == 0
    # the solution of the condensed problem satisfies the global equations
    s = solve(p, method="newton", tol=1e-12)
    v = np.linalg.solve(g.M.toarray(), Hd @ s.r + g.f)
    np.testing.assert_allclose(Hd.T @ v + g.w, s.u, atol=1e-10)


def _write_triplet(path, A, q, mu, nzmax_extra=0):
    A = sp.coo_matrix(A)
    with h5py.File(path, "w") as h5:
        g = h5.create_group("fclib_local")
        g["spacedim"] = np.array([3], np.int32)
        n = A.shape[0]
        for k, v in (("m", n), ("n", n), ("nz", A.nnz), ("nzmax", A.nnz + nzmax_extra)):
            g[f"W/{k}"] = np.array([v], np.int32)
        pad = np.zeros(nzmax_extra)
        g["W/i"] = np.r_[A.row, pad].astype(np.int32)   # CSparse triplet: i = row
        g["W/p"] = np.r_[A.col, pad].astype(np.int32)   #                  p = column
        g["W/x"] = np.r_[A.data, pad]
        g["vectors/q"], g["vectors/mu"] = q, mu


def test_triplet_and_csc_layouts(tmp_path):
    p = random_problem(seed=3)
    _write_triplet(tmp_path / "t.hdf5", p.W, p.q, p.mu_bar, nzmax_extra=5)
    back = read_fclib(tmp_path / "t.hdf5")
    np.testing.assert_array_equal(back.W.toarray(), p.W.toarray())
    # an unsymmetric matrix tells rows from columns
    A = sp.csr_matrix(np.triu(np.arange(1.0, 37.0).reshape(6, 6)))
    _write_triplet(tmp_path / "u.hdf5", A, np.zeros(6), np.ones(2))
    np.testing.assert_array_equal(read_fclib(tmp_path / "u.hdf5").W.toarray(), A.toarray())
    g = global_problem()
    write_fclib_global(tmp_path / "c.hdf5", g)
    with h5py.File(tmp_path / "c.hdf5") as h5:
        assert int(h5["fclib_global/M/nz"][0]) == -1


@pytest.mark.parametrize("damage, name", [
    (lambda h5: h5.__delitem__("fclib_local/vectors/q"), "fclib_local/vectors/q"),
    (lambda h5: h5.__delitem__("fclib_local/W/p"), "fclib_local/W/p"),
    (lambda h5: (h5.__delitem__("fclib_local/vectors/mu"),
                 h5.__setitem__("fclib_local/vectors/mu", np.ones(3))), "fclib_local/vectors/mu"),
    (lambda h5: (h5.__delitem__("fclib_local/W/nz"),
                 h5.__setitem__("fclib_local/W/nz", np.array([-7], np.int32))), "fclib_local/W/nz"),
    (lambda h5: (h5.__delitem__("fclib_local/W/i"),
                 h5.__setitem__("fclib_local/W/i", np.full(200, 99, np.int32))), "fclib_local/W/i"),
])
def test_malformed_file_names_the_dataset(tmp_path, damage, name):
    path = write_fclib(tmp_path / "p.hdf5", random_problem())
    with h5py.File(path, "a") as h5:
        damage(h5)
    with pytest.raises(FrictionRulesError, match=name.replace("/", "/")):
        read_fclib(path)


def test_truncated_and_foreign_files(tmp_path):
    path = write_fclib(tmp_path / "p.hdf5", random_problem())
    data = path.read_bytes()
    (tmp_path / "cut.hdf5").write_bytes(data[: len(data) // 2])
    with pytest.raises(FrictionRulesError, match="fclib|HDF5|dataset"):
        read_fclib(tmp_path / "cut.hdf5")
    with h5py.File(tmp_path / "empty.hdf5", "w") as h5:
        h5["x"] = 1
    with pytest.raises(FrictionRulesError, match="fclib_local"):
        read_fclib(tmp_path / "empty.hdf5")
    with pytest.raises(FileNotFoundError):
        read_fclib(tmp_path / "missing.hdf5")


def test_write_refuses_non_coulomb_laws(tmp_path):
    from frictionrules import EllipticOrthotropic
    p = FrictionContactProblem(np.eye(3), np.zeros(3), [EllipticOrthotropic(0.5, 0.2)])
    with pytest.raises(FrictionRulesError, match="Coulomb"):
        write_fclib(tmp_path / "x.hdf5", p)
    assert not list(tmp_path.iterdir())


@needs_fclib
def test_reads_every_shared_file():
    for f in sorted(FCLIB.glob("*.hdf5")):
        p = read_fclib(f)
        assert p.nc >= 1 and p.W.shape == (3 * p.nc, 3 * p.nc)
        assert np.all(p.mu_bar > 0)


@needs_fclib
def test_stored_siconos_solution_of_spheres_pile():
    """SpheresPile stores the simulation's own Siconos NSGS solution (maxiter 100): u = W r + q
    exactly and Siconos' error 6.4e-3 (README); our reader and error measure reproduce both."""
    from frictionrules.multicontact import fc3d_error
    path = FCLIB / "SpheresPile-nc1812.hdf5"
    p = read_fclib(path)
    with h5py.File(path) as h5:
        r, u = h5["solution/r"][()], h5["solution/u"][()]
    assert np.linalg.norm(p.W @ r + p.q - u) <= 1e-12 * np.linalg.norm(u)
    assert fc3d_error(p, r, u) == pytest.approx(6.4e-3, rel=0.01)


@pytest.mark.parametrize("dense_max", [400, 0], ids=["dense", "sparse"])
def test_singular_mass_matrix_is_refused_in_one_line(monkeypatch, dense_max):
    import frictionrules.io as fio
    monkeypatch.setattr(fio, "DENSE_CONDENSE_MAX", dense_max)
    g = global_problem()
    M = g.M.toarray()
    M[:, 0] = 0.0
    M[0, :] = 0.0
    bad = GlobalProblem(sp.csc_matrix(M), g.H, g.f, g.w, g.mu)
    with pytest.raises(FrictionRulesError, match="fclib_global/M is singular"):
        bad.condense()
