"""Tools of the dynamic (DEM) engine: the command line with ``method = "dem"``, the figures of a
dynamic run, and the VTK files for ParaView read back through meshio."""

import dataclasses
import io
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from frictionrules import Assembly, ContactModel, Coulomb, FrictionRulesError, triaxial, write_vtk


@pytest.fixture(scope="module")
def disks():
    """A random packing of 30 disks sheared biaxially by the dynamic engine to 0.5 %."""
    a = Assembly.random(30, 2, ContactModel(Coulomb(0.5), kn=1e4, kt=1e4), polydispersity=0.2,
                        seed=5)
    return a, triaxial(a, "biaxial", pressure=1.0, axial_strain=5e-3, method="dem")


@pytest.fixture(scope="module")
def spheres():
    """40 spheres in axisymmetric compression to 0.5 %."""
    a = Assembly.random(40, 3, ContactModel(Coulomb(0.5), kn=1e4, kt=1e4), polydispersity=0.2,
                        seed=5)
    return a, triaxial(a, "axisymmetric", pressure=1.0, axial_strain=5e-3, method="dem")


# ---- VTK ---------------------------------------------------------------------------------------
def _collection(path):
    """``(timestep, file)`` of each data set of a ``.pvd`` collection."""
    root = ET.parse(path).getroot()
    assert root.get("type") == "Collection"
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


@pytest.mark.parametrize("sample", ["disks", "spheres"])
def test_vtk_files_read_back_hold_the_records(sample, request, tmp_path):
    """Every written record's grains and contacts come back through meshio with the result's
    values; a contact's line runs from grain i to the image of j that touches it, so a
    force-carrying contact is as long as r_i + r_j less its overlap N/kn, across the periodic
    boundary too; the cell's corners are the record's cell vectors."""
    assembly, result = request.getfixturevalue(sample)
    files = write_vtk(result, tmp_path / "vtk", every=2)
    assert [f.name for f in files] == ["grains.pvd", "contacts.pvd", "cell.pvd"]
    count = len(result.time)
    chosen = sorted(set(range(0, count, 2)) | {count - 1})
    d = assembly.dim
    crossing = 0
    for pvd in files:
        entries = _collection(pvd)
        assert [t for t, _ in entries] == [result.time[k] for k in chosen]
        assert [name for _, name in entries] == [f"{pvd.stem}_{k:06d}.vtu" for k in chosen]
    for k in chosen:
        x, h, snap = result.positions[k], result.cells[k], result.contacts[k]
        grains = meshio.read(tmp_path / "vtk" / f"grains_{k:06d}.vtu")
        assert grains.points.shape == (assembly.size, 3)
        np.testing.assert_array_equal(grains.point_data["radius"], assembly.radii)
        np.testing.assert_allclose(grains.point_data["displacement"][:, :d], x - result.positions[0])
        frac = np.linalg.solve(h, grains.points[:, :d].T).T  # wrapped into the cell
        assert frac.min() >= -1e-12 and frac.max() < 1 + 1e-12
        if d == 2:
            assert not grains.points[:, 2].any()
        lines = meshio.read(tmp_path / "vtk" / f"contacts_{k:06d}.vtu")
        cells = lines.cells_dict["line"]
        assert len(cells) == snap.size and lines.points.shape == (2 * snap.size, 3)
        data = {name: v[0] for name, v in lines.cell_data.items()}
        np.testing.assert_array_equal(data["normal_force"], snap.force[:, 2])
        np.testing.assert_array_equal(data["tangential_force"], np.hypot(*snap.force[:, :2].T))
        np.testing.assert_array_equal(data["status"], snap.status)
        np.testing.assert_array_equal(data["grains"], snap.grains)
        # the global force of j on i: its normal component is -N, its tangential one |T|
        normal = np.einsum("ck,ck->c", data["force"], snap.frame[:, 2])
        np.testing.assert_allclose(normal, -snap.force[:, 2], atol=1e-12 * snap.force[:, 2].max())
        branch = lines.points[cells[:, 1], :d] - lines.points[cells[:, 0], :d]
        i, j = snap.grains.T
        carrying = snap.force[:, 2] > 0
        # touching: r_i + r_j less the overlap N/kn (of the last force update, the centres at
        # the leapfrog's half step); any other image of j is a cell width (> 4 radii) away
        touching = assembly.radii[i] + assembly.radii[j] - snap.force[:, 2] / 1e4
        np.testing.assert_allclose(np.linalg.norm(branch, axis=1)[carrying], touching[carrying],
                                   rtol=1e-3)
        np.testing.assert_allclose(lines.points[cells[:, 0], :d], grains.points[i, :d])
        crossing += np.count_nonzero(np.any(snap.shift != 0, axis=1) & carrying)
        cell = meshio.read(tmp_path / "vtk" / f"cell_{k:06d}.vtu")
        corners = [1, 3, 4][:d]  # the corners at the ends of the cell vectors (VTK's order)
        np.testing.assert_allclose(cell.points[corners, :d], h.T)
    assert crossing > 0  # the periodic images were exercised


def test_write_vtk_refuses_an_implicit_result_and_a_bad_every(disks, tmp_path):
    lattice = Assembly.lattice("hex2d", ContactModel(Coulomb(0.3), kn=1e4, kt=1e4))
    implicit = triaxial(lattice, "biaxial", pressure=1.0, axial_strain=1e-5, increments=2)
    with pytest.raises(FrictionRulesError, match="method = 'implicit' has no positions"):
        write_vtk(implicit, tmp_path)
    with pytest.raises(FrictionRulesError, match="every = 0 violates"):
        write_vtk(disks[1], tmp_path, every=0)


# ---- figures -----------------------------------------------------------------------------------
def test_dem_figures(disks, spheres):
    """The four panels; the force network at a middle record draws its force-carrying
    contacts (from that record's positions) with widths ∝ N."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.collections as mc
    import matplotlib.pyplot as plt

    from frictionrules.plot.assembly import force_network, plot_coordination, plot_dem_run
    for assembly, result in (disks, spheres):
        axes = plot_dem_run(result, increment=2)
        assert axes.shape == (2, 2)
        (network,) = [c for c in axes[1, 1].collections if isinstance(c, mc.LineCollection)]
        snap = result.contacts[2]
        carrying = snap.force[:, 2] > 0
        assert len(network.get_segments()) == np.count_nonzero(carrying)
        widths = network.get_linewidths()
        np.testing.assert_allclose(widths, 3 * snap.force[carrying, 2] / snap.force[carrying, 2].max())
        peak = [h for h in axes[0, 0].lines if h.get_label() == "peak of the running mean"]
        assert len(peak) == int(result.failed)  # a dotted line at the running mean's peak
        if result.failed:
            np.testing.assert_array_equal(peak[0].get_ydata(), [result.peak_ratio] * 2)
        plt.close(axes[0, 0].figure)
    ax, right = plot_coordination(disks[1])
    np.testing.assert_array_equal(ax.lines[1].get_ydata(), disks[1].coordination_without_rattlers)
    np.testing.assert_array_equal(right.lines[0].get_ydata(), disks[1].sliding_fraction)
    plt.close(ax.figure)
    ax = force_network(spheres[1], -1, plane="yz")
    assert ax.get_xlabel() == "y" and ax.get_ylabel() == "z"
    plt.close(ax.figure)


def test_force_network_of_a_slab(spheres):
    """In 3-D the network of a slab about the cell's middle plane: the force-carrying
    contacts whose branch midpoints are within half the thickness of it (here the plane xz,
    so |y_mid - H_yy/2| ≤ slab/2 in the rectangular cell); a bad thickness is an error."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.collections as mc
    import matplotlib.pyplot as plt

    from frictionrules import FrictionRulesError
    from frictionrules.plot.assembly import force_network
    result = spheres[1]
    snap, x, h = result.contacts[-1], result.positions[-1], result.cells[-1]
    assert np.allclose(h, np.diag(np.diag(h)))
    i, j = snap.grains.T
    wrapped = np.mod(x, np.diag(h))
    mid = wrapped[i] + 0.5 * (x[j] + snap.shift @ h.T - x[i])
    thickness = 0.3 * h[1, 1]
    inside = (snap.force[:, 2] > 0) & (np.abs(mid[:, 1] - 0.5 * h[1, 1]) <= 0.5 * thickness)
    assert 0 < np.count_nonzero(inside) < np.count_nonzero(snap.force[:, 2] > 0)
    ax = force_network(result, -1, plane="xz", slab=thickness)
    (network,) = [c for c in ax.collections if isinstance(c, mc.LineCollection)]
    assert len(network.get_segments()) == np.count_nonzero(inside)
    plt.close(ax.figure)
    with pytest.raises(FrictionRulesError, match="slab = -1.0 violates"):
        force_network(result, -1, slab=-1.0)


# ---- command line ------------------------------------------------------------------------------
LATTICE = ('[sample]\nlattice = "hex2d"\ncells = [4, 4]\n[model]\nkn = 1e4\nkt = 1e4\n[model.law]\n'
           'type = "Coulomb"\nmu = 0.3\n[loading]\nkind = "biaxial"\npressure = 1.0\n'
           'axial_strain = 5e-3\nmethod = "dem"\nrecord_every = 1e-3\n')


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "frictionrules", "assembly", *map(str, args)],
                          capture_output=True, text=True)


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_cli_dem_run_writes_its_outputs_and_resumes(tmp_path, monkeypatch, capsys):
    """A run shows its stages and records on a terminal, prints the peak, the end of the run
    and the energy balance, and writes the figure and the VTK files. Stopped at once
    (--max-time): no peak, exit 1, the run file kept; run again, it resumes to the same end."""
    from frictionrules.cli import main
    cfg = tmp_path / "hex.toml"
    cfg.write_text(LATTICE)
    terminal = _Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    assert main(["assembly", str(cfg), "--out", str(tmp_path / "full.h5"), "--figure",
                 str(tmp_path / "hex.png"), "--vtk", str(tmp_path / "vtk"), "--vtk-every", "2"]) == 0
    shown = terminal.getvalue()
    assert "consolidation: p/p* = " in shown and "\r" in shown
    assert "5/5 records" in shown
    text = capsys.readouterr().out
    assert re.search(r"32 grains, 5 records \(completed\); peak σ1/σ3 = [\d.]+ \(running mean\), "
                     r"friction angle [\d.]+ deg", text), text
    assert re.search(r"at axial strain 0\.005\d*: σ1/σ3 [\d.]+ \(friction angle [\d.]+ deg\), "
                     r"volumetric strain -?[\d.e-]+, Z 4 \(4 without rattlers\)", text), text
    assert re.search(r"energy balance: error [\d.e-]+ % of the boundary work", text), text
    assert (tmp_path / "hex.png").stat().st_size > 10_000
    assert [name for _, name in _collection(tmp_path / "vtk" / "contacts.pvd")] == [
        f"contacts_{k:06d}.vtu" for k in (0, 2, 4, 5)]
    out = tmp_path / "hex.h5"
    stop = _cli(cfg, "--out", out, "--max-time", "1e-9", "--quiet")
    assert stop.returncode == 1, stop.stderr
    assert "no peak reached before the run stopped" in stop.stdout  # where: the clock says
    assert "inf" not in stop.stdout and out.exists()
    again = _cli(cfg, "--out", out, "--quiet")
    assert again.returncode == 0 and again.stdout.splitlines()[:3] == text.splitlines()[:3]


@pytest.mark.parametrize("line, named", [
    ("damping = 1.5", "damping = 1.5 violates damping < 1.0"),
    ("inertial_number = -4e-4", "inertial_number = -0.0004 violates inertial_number > 0.0"),
    ('density = "heavy"', "density = 'heavy' is not a real number"),
    ("record_every = 0.0", "record_every = 0.0 violates record_every > 0.0"),
    ('method = "explicit"', "method = 'explicit' violates: one of implicit, dem"),
    ('cell = "skewed"', "cell = 'skewed' violates: one of rectangular, flexible"),
])
def test_cli_bad_dem_option_is_one_line(tmp_path, line, named):
    """A bad option of the dynamic engine is refused before the sample is built: exit 2, one
    line naming the file, the key, the value and the constraint."""
    cfg = tmp_path / "bad.toml"
    key = line.split(" = ")[0]  # [loading] is the last table: the line replaces the key's
    cfg.write_text("".join(f"{kept}\n" for kept in LATTICE.splitlines()
                           if not kept.startswith(f"{key} = ")) + f"{line}\n")
    res = _cli(cfg, "--out", tmp_path / "bad.h5")
    assert res.returncode == 2 and res.stderr.count("\n") == 1, res.stderr
    assert str(cfg) in res.stderr and "[loading]" in res.stderr and named in res.stderr
    assert not (tmp_path / "bad.h5").exists()


def test_cli_dem_options_need_the_dem_method_and_vtk_needs_records(tmp_path):
    cfg = tmp_path / "implicit.toml"
    implicit = LATTICE.replace('method = "dem"\nrecord_every = 1e-3\n', "increments = 2\n")
    cfg.write_text(implicit + "damping = 0.1\n")
    res = _cli(cfg, "--out", tmp_path / "r.h5")
    assert res.returncode == 2 and res.stderr.count("\n") == 1
    assert ("[loading] damping violates: options of method = \"dem\" only (method = 'implicit')"
            in res.stderr)
    cfg.write_text(implicit)
    res = _cli(cfg, "--out", tmp_path / "r.h5", "--vtk", tmp_path / "vtk")
    assert res.returncode == 2 and res.stderr.count("\n") == 1 and "--vtk" in res.stderr
    assert not (tmp_path / "r.h5").exists()


def test_dem_summary_of_a_run_stopped_before_its_peak(disks):
    """A run stopped (max_time) before a peak says how far it came, never an infinite strength,
    and the command exits 1; completed without a peak, it says so and exits 0."""
    from frictionrules.cli.assembly import _dem_summary, _exit_code
    assembly, result = disks
    stopped = dataclasses.replace(result, failed=False, peak_ratio=np.inf, peak_friction_angle=90.0,
                                  message="stopped after 5 records: max_time = 1.0 s reached")
    text = _dem_summary(assembly, stopped)
    assert (f"no peak reached before the run stopped at axial strain {result.axial_strain[-1]:.6g} "
            f"(largest σ1/σ3 {result.stress_ratio.max():.6g})") in text
    assert "inf" not in text and _exit_code(stopped, dem=True) == 1
    completed = dataclasses.replace(stopped, message="completed")
    assert "no peak up to axial strain" in _dem_summary(assembly, completed)
    assert _exit_code(completed, dem=True) == 0 and _exit_code(result, dem=True) == 0

