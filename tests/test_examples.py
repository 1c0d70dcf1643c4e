"""Examples in ``examples/`` and the README's snippets are tested scripts: each runs and gives
its headline numbers."""

import importlib.util
import re
import runpy
from pathlib import Path

import numpy as np
import pytest

from test_io import FCLIB, needs_fclib

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


@pytest.fixture(autouse=True)
def empty_working_folder(tmp_path, monkeypatch):
    """Every example runs in an empty working folder and leaves it empty: outputs go only
    where they are asked to go."""
    cwd = tmp_path / "cwd"
    cwd.mkdir()
    monkeypatch.chdir(cwd)
    yield
    assert not list(cwd.iterdir()), "an example wrote into the working folder"


def load(name):
    """Import ``examples/<name>.py`` as a module (its ``main`` is called by the tests)."""
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# ---- laws and README -----------------------------------------------------------------
def test_example_orthotropic(tmp_path):
    mod = runpy.run_path(str(ROOT / "examples" / "laws_orthotropic.py"))
    deviation = mod["main"](out_dir=tmp_path)
    assert deviation["EllipticOrthotropic"] < 1e-9  # normality in the sliding plane
    assert deviation["Huber"] > 5 and deviation["TransformedCoulomb"] > 5
    assert (tmp_path / "orthotropic.png").stat().st_size > 1000


def test_example_run_as_a_script_writes_its_figure_into_the_current_folder(capsys):
    """``python examples/laws_orthotropic.py`` saves the figure in the current folder and says
    so by its relative name (the gallery runs every example this way)."""
    import os
    runpy.run_path(str(EXAMPLES / "laws_orthotropic.py"), run_name="__main__")
    assert Path("orthotropic.png").stat().st_size > 1000
    assert "wrote orthotropic.png" in capsys.readouterr().out
    os.remove("orthotropic.png")                # the working folder stays empty


def test_every_example_saves_a_figure_when_run_as_a_script():
    """Each script's ``__main__`` passes the current folder to ``main(out_dir=...)``."""
    for script in EXAMPLES.glob("*.py"):
        text = script.read_text()
        assert 'main(out_dir=".")' in text.split('if __name__ == "__main__":')[-1], script.name
        assert "in the current folder" in text, script.name


def test_readme_python_example_runs(capsys):
    text = (ROOT / "README.md").read_text()
    code = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    exec(compile(code, "README.md", "exec"), {})
    out = capsys.readouterr().out
    assert "ellipse" in out


def test_readme_quick_start_has_exactly_two_commands():
    text = (ROOT / "README.md").read_text()
    block = re.search(r"## Quick start.*?```bash\n(.*?)```", text, re.S).group(1)
    commands = [line for line in block.splitlines() if line.strip() and not line.startswith("#")]
    assert len(commands) == 2
    assert "frictionrules paper --out figures" in commands[0]
    assert "pytest" in commands[1]
    assert commands[1] in (ROOT / ".ci" / "run").read_text()  # CI runs exactly this command


def test_every_example_is_tested():
    text = Path(__file__).read_text()
    for script in EXAMPLES.glob("*.py"):
        assert f'"{script.stem}"' in text or f"{script.name}" in text, script.name


@pytest.mark.parametrize("doc", ["docs/conventions.md", "docs/errata.md", "docs/laws.md",
                                 "docs/asperities.md", "docs/configuration.md", "docs/contact.md",
                                 "docs/multicontact.md", "benchmarks/README.md"])
def test_docs_exist(doc):
    assert (ROOT / doc).stat().st_size > 500


# ---- asperities (§2) -----------------------------------------------------------------
def test_asperity_two_flank_example(capsys):
    mu_y = load("asperity_two_flank").main()
    # distance from the origin to the line (2.12): (s1 + s2) / sqrt((c1 + c2)^2 + sin^2(a2 - a1))
    a1, a2 = np.pi / 3, 5 * np.pi / 6
    want = (np.sin(a1) + np.sin(a2)) / np.hypot(np.cos(a1) + np.cos(a2), np.sin(a2 - a1))
    assert mu_y == pytest.approx(want, rel=1e-9)
    assert "226.67" in capsys.readouterr().out


def test_asperity_heightmap_fit_example(tmp_path):
    rms = load("asperity_heightmap_fit").main(n=128, out_dir=tmp_path)
    assert rms < 0.05 and (tmp_path / "asperity_heightmap_fit.png").stat().st_size > 1000


def test_asperity_measured_surface_example(tmp_path, capsys):
    """The stylus profile of ../shared/surfaces at the default scale (the maps are the same
    code, tested in test_topography_files.py)."""
    from test_topography_files import shared
    shared("opdx-3.opdx")
    rows, _ = load("asperity_measured_surface").main(files=("opdx-3.opdx",))
    r = rows[0]["result"]
    assert 0.3 <= r.mu_range[0] <= r.mu_range[1] <= r.upper_bound
    assert "opdx-3.opdx  scale 0.08328" in capsys.readouterr().out


def test_asperity_machined_local_law_example():
    mu = load("asperity_machined_local_law").main(n=64)
    coulomb, machined = mu["Coulomb 0.2"], mu["machined: 0.25 across, 0.12 along the lay"]
    assert machined[0] > coulomb[0] and machined[2] < coulomb[2]   # across / along the lay
    assert np.all(np.isfinite(mu["dilatant machined (g = f)"]))


# ---- configuration softening (§3) ----------------------------------------------------
def test_cylinder_softening_example():
    out = load("configuration_cylinder_softening").main()
    assert out["order"] == pytest.approx(1.0, abs=0.1)
    assert out["limit_force"] == pytest.approx(np.tan(np.pi / 6 + np.arctan(0.3)), rel=1e-9)


def test_sphere_pocket_example():
    out = load("configuration_sphere_pocket").main()
    assert out["ridge_peak"] == pytest.approx(0.7977, abs=1e-4)     # force at 60 deg, over two
    assert out["over_one_peak"] == pytest.approx(np.tan(np.arcsin(3**-0.5) + np.arctan(0.3)))


def test_configuration_orthotropic_example():
    """Orthotropic grain contacts: force control reaches the break-out force, displacement
    control starts there and softens, the rate form agrees with the exact path."""
    out = load("configuration_orthotropic").main()
    assert out["limit_point"] == pytest.approx(out["start"], rel=1e-9)
    assert out["end"] < 0.5 * out["start"]
    assert out["rate_error"] < 1e-4


# ---- elastic-plastic contact (§4) ----------------------------------------------------
def test_fig10_shear_example(tmp_path):
    out = load("contact_fig10_shear").main(out_dir=tmp_path)
    assert (tmp_path / "contact_fig10_shear.png").stat().st_size > 1000
    assert out[0.4]["peak"] == pytest.approx(0.4803, abs=1e-3)
    assert out[0.4]["final_ratio"] == pytest.approx(0.6, rel=0.01)
    assert out[1.6]["final_ratio"] == pytest.approx(0.6, rel=0.01)


def test_batched_update_example():
    out = load("contact_batched_update").main(n=20_000)
    assert out["plastic"] == 1.0
    assert out["mu_min"] == pytest.approx(0.3, rel=1e-3) and out["mu_max"] == pytest.approx(0.6, rel=1e-3)


def test_drive_toml_example_parses():
    from frictionrules.contact.driver import read_toml
    model, path, opts = read_toml(EXAMPLES / "contact_shear.toml")
    assert len(path) == 410 and opts["beta"] == 0.5


# ---- many contacts -------------------------------------------------------------------
def test_wedge_stack_onset_is_wedge_limit_eq_2_2():
    out = load("multicontact_wedge_stack").main()
    assert out["onset"] == pytest.approx(out["closed_form"], rel=1e-9)


def test_orthotropic_block_slip_obeys_inverse_relation_eq_1_13():
    out = load("multicontact_orthotropic_block").main()
    assert out["inverse_gap"] < 1e-12
    assert abs(out["slip_deg"] - 45.0) > 30.0  # the slip is far from the push direction


@needs_fclib
def test_fclib_example_solves_capsules():
    errors = load("multicontact_fclib").main(FCLIB / "Capsules-i125-1213.hdf5")
    assert min(errors.values()) <= 1e-8
    assert np.isfinite(list(errors.values())).all()


# ---- grain assemblies ----------------------------------------------------------------------
def test_example_assembly_thornton_fcc(tmp_path):
    out = load("assembly_thornton_fcc").main(out_dir=tmp_path)
    for (mu, dilatant), row in out.items():
        if mu < 1:
            assert row["peak"] == pytest.approx(row["exact"], rel=1e-3)
    assert out[(0.3, True)]["dilatancy"] == pytest.approx(-(1 + 0.9) / 0.7, rel=2e-3)
    assert out[(1.2, False)]["peak"] == np.inf
    assert (tmp_path / "assembly_thornton_fcc.png").stat().st_size > 1000


def test_example_assembly_rules_plane_strain(tmp_path):
    out = load("assembly_rules_plane_strain").main(out_dir=tmp_path)
    assert out["non-associated"] == pytest.approx(2 * (6**0.5 + 0.6) / (6**0.5 - 1.2), rel=1e-3)
    assert out["associated"] > 1.01 * out["non-associated"]


def test_example_assembly_hex2d_rowe(tmp_path):
    out = load("assembly_hex2d_rowe").main(out_dir=tmp_path)
    assert out["D"] == pytest.approx(3.0, rel=1e-3)
    assert (tmp_path / "assembly_hex2d_rowe.png").stat().st_size > 1000


def test_example_assembly_dem_paraview(tmp_path, capsys):
    """The docs' picture of the force chains: a dynamic run's VTK files written, read back and
    drawn."""
    out = load("assembly_dem_paraview").main(out_dir=tmp_path, n=40, axial_strain=2e-3)
    assert out["records"] == 3 and out["contacts"] > 40
    assert (tmp_path / "assembly_dem_force_chains.png").stat().st_size > 20_000
    assert sorted(p.name for p in (tmp_path / "vtk").glob("*.pvd")) == [
        "cell.pvd", "contacts.pvd", "grains.pvd"]
    assert "energy balance error" in capsys.readouterr().out


def test_example_assembly_orthotropic_fcc():
    out = load("assembly_orthotropic_fcc").main()
    for peak in out.values():
        assert peak == pytest.approx(1.2 / 0.8 + 1.4 / 0.6, rel=1e-3)


# ---- MuJoCo scenes stepped by the library ------------------------------------------------------
def test_mujoco_sled_ratchets_on_the_sawtooth_and_not_on_the_ellipse():
    """The sled driven by an internal oscillating mass: on the wedge (sawtooth) law it moves
    towards -x, the easy side of the flanks (tan(rho - alpha) against tan(rho + alpha)); on
    the symmetric elliptic law (library and MuJoCo's own) it only rocks (the few mm of the
    start-up transient). Needs the extra mujoco (fails on CI without it)."""
    import os
    if os.environ.get("CI") != "true":
        pytest.importorskip("mujoco", reason="the extra mujoco is not installed")
    out = load("mujoco_snake_sled").main(seconds=1.0)
    saw, ours, theirs = (out[k] for k in ("sawtooth", "elliptic (frictionrules)", "elliptic (MuJoCo)"))
    assert saw[0] < -0.02 and saw[1] < 0
    assert abs(ours[0]) < 0.01 and abs(theirs[0]) < 0.01
    assert saw[0] < 4 * ours[0]
