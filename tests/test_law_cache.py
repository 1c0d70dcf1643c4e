"""The disk cache of what SymPy derives for a law's compiled kernel
(:mod:`frictionrules.contact._lawcache`): a hit gives the derived entry bit for bit and needs no
SymPy, a stale or corrupt entry is derived again and written over, and processes writing the
same entry at once leave a whole one."""

from __future__ import annotations

import json
import multiprocessing
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from frictionrules import (Coulomb, EllipsoidCap, EllipticOrthotropic, HardenedLaw, SlipHardening,
                           UserLaw)
from frictionrules.contact import _generated, _lawcache

pytest.importorskip("sympy")

SRC = Path(__file__).resolve().parents[1] / "src"

LAWS = {
    "coulomb": Coulomb(0.4),
    "cap": EllipsoidCap.from_parameters(m=0.6, p=2.0, h=0.25, kappa_h=0.05, b=20.0),
    "hardened": HardenedLaw(EllipticOrthotropic(0.3, 0.6, angle=0.4), SlipHardening(0.5, 0.02)),
    "user": UserLaw("sqrt(T1**2 + T2**2) - mu*N", params={"mu": 0.3}),
}


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """An empty cache folder for this test; the per-process memo cleared before and after."""
    monkeypatch.setenv("FRICTIONRULES_CACHE_DIR", str(tmp_path))
    _generated.law_entry.cache_clear()
    yield _generated.cache_dir()
    _generated.law_entry.cache_clear()


class _Spy:
    """Counts the derivations with SymPy (``_generated._derive``)."""

    def __init__(self, monkeypatch):
        self.calls = 0
        derive = _generated._derive

        def spy(law, folder):
            self.calls += 1
            return derive(law, folder)
        monkeypatch.setattr(_generated, "_derive", spy)


def _bits(a):
    return np.asarray(a, dtype=float).view(np.int64).tolist()


def _fresh(law):
    _generated.law_entry.cache_clear()
    return _generated.law_entry(law)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_a_hit_gives_the_derived_entry_and_row_bit_for_bit(cache, name, monkeypatch):
    """The first call derives the law and writes its entry; a later one (a new process's view:
    the memo cleared) reads it without deriving: the same module, the same constants and
    parameter values to the bit, so the same row for the compiled kernel (the module's text,
    and so its machine code, is the derivation's own: its digest is checked)."""
    law = LAWS[name]
    spy = _Spy(monkeypatch)
    derived, path = _fresh(law)
    row = _generated.law_row(law, 3.0, 7.0)
    assert spy.calls == 1 and path.exists() and len(list(cache.glob("law-*.json"))) == 1
    hit, path2 = _fresh(law)
    assert spy.calls == 1 and path2 == path
    assert (hit.module, hit.module_sha256, hit.nq) == (derived.module, derived.module_sha256,
                                                       derived.nq)
    for field in ("return_constants", "parameter_values"):
        assert _bits(getattr(hit, field)) == _bits(getattr(derived, field))
    assert _bits(_generated.law_row(law, 3.0, 7.0)) == _bits(row)
    # the derivation from scratch (no cache at all) gives the same numbers
    from frictionrules.codegen import return_constants
    from frictionrules.laws import form_of
    assert _bits(hit.return_constants) == _bits(return_constants(form_of(law)))
    assert _bits(hit.parameter_values) == _bits(_generated.parameter_values(law))


def test_laws_differing_in_values_share_the_module_not_the_entry(cache, monkeypatch):
    spy = _Spy(monkeypatch)
    a, _ = _fresh(Coulomb(0.3))
    b, _ = _fresh(Coulomb(0.5))
    assert spy.calls == 2 and a.module == b.module
    assert len(list(cache.glob("law-*.json"))) == 2 and len(list(cache.glob("*.py"))) == 1
    assert _bits(a.parameter_values) != _bits(b.parameter_values)


def _corrupt_json(path, folder):
    path.write_text(path.read_text()[:40])


def _other_key(path, folder):
    doc = json.loads(path.read_text())
    doc["key"] = _lawcache.law_key(Coulomb(0.5))
    path.write_text(json.dumps(doc))


def _bad_float(path, folder):
    doc = json.loads(path.read_text())
    doc["parameter_values"][0] = 0.4
    path.write_text(json.dumps(doc))


def _module_edited(path, folder):
    module = next(folder.glob("frictionrules_law_*.py"))
    module.write_text(module.read_text() + "\n# edited\n")


def _module_gone(path, folder):
    next(folder.glob("frictionrules_law_*.py")).unlink()


def _not_a_module_name(path, folder):
    doc = json.loads(path.read_text())
    doc["module"] = "../elsewhere"
    path.write_text(json.dumps(doc))


def _not_a_generated_module(path, folder):
    doc = json.loads(path.read_text())
    module = folder / f"{doc['module']}.py"
    (folder / "json.py").write_bytes(module.read_bytes())
    doc["module"] = "json"
    path.write_text(json.dumps(doc))


def _older_format(path, folder):
    doc = json.loads(path.read_text())
    doc["format"] = _lawcache.FORMAT - 1
    path.write_text(json.dumps(doc))


@pytest.mark.parametrize("damage", [_corrupt_json, _other_key, _bad_float, _module_edited,
                                    _module_gone, _not_a_module_name, _not_a_generated_module,
                                    _older_format])
def test_a_corrupt_or_stale_entry_is_derived_again_and_written_over(cache, damage, monkeypatch):
    """A truncated entry, one that repeats another key, a value that is not a hex float, a
    module whose text is not the one recorded (edited, or another version's under the same
    name), a missing module, a module name that is not a plain name or not a generated
    module's (even with the recorded text), an older format: each is
    a miss; the law is derived again and the entry rewritten (the next call hits)."""
    law = LAWS["coulomb"]
    spy = _Spy(monkeypatch)
    first, _ = _fresh(law)
    entry = next(cache.glob("law-*.json"))
    damage(entry, cache)
    again, path = _fresh(law)
    assert spy.calls == 2 and path.exists()
    assert _bits(again.parameter_values) == _bits(first.parameter_values)
    _fresh(law)
    assert spy.calls == 2


def test_another_generator_is_another_key(cache, monkeypatch):
    """The key holds the digest of the generator's sources (and the library's and SymPy's
    versions): a change of any is a miss, not a stale hit."""
    law = LAWS["coulomb"]
    spy = _Spy(monkeypatch)
    _fresh(law)
    key = _lawcache.law_key(law)
    monkeypatch.setattr(_lawcache, "generator_digest", lambda: "0" * 64)
    assert _lawcache.law_key(law) != key
    _fresh(law)
    assert spy.calls == 2 and len(list(cache.glob("law-*.json"))) == 2


def test_the_generator_digest_follows_the_sources():
    """The sources the digest reads are the ones that exist (a renamed file would fail here,
    not silently leave the cache keyed on less)."""
    root = Path(_lawcache.__file__).resolve().parents[1]
    for name in _lawcache._SOURCES:
        assert (root / name).exists(), name
    assert len(_lawcache.generator_digest()) == 64


_TWO_RUNS = """
    import json, sys
    from frictionrules import EllipsoidCap
    from frictionrules.contact._generated import law_row
    law = EllipsoidCap.from_parameters(m=0.6, p=2.0, h=0.25, kappa_h=0.05, b=20.0)
    row = law_row(law, 3.0, 7.0)
    print(json.dumps({"row": [float(v).hex() for v in row], "sympy": "sympy" in sys.modules}))
"""


def _python(code, folder):
    env = dict(os.environ, PYTHONPATH=str(SRC), FRICTIONRULES_CACHE_DIR=str(folder))
    proc = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout)


def test_a_later_process_does_not_import_sympy(tmp_path):
    """The point of the cache: a second process with the same folder builds the law's row
    without importing SymPy, and gets the first one's row to the bit."""
    first = _python(_TWO_RUNS, tmp_path)
    second = _python(_TWO_RUNS, tmp_path)
    assert first["sympy"] and not second["sympy"]
    assert second["row"] == first["row"]


def _derive_in_a_process(folder, queue):
    os.environ["FRICTIONRULES_CACHE_DIR"] = str(folder)
    from frictionrules.contact import _generated
    law = LAWS["cap"]
    entry, path = _generated.law_entry(law)
    queue.put((entry.module, entry.module_sha256, _bits(entry.parameter_values)))


def _write_many(folder, key, entry, rounds):
    for _ in range(rounds):
        _lawcache.write_entry(Path(folder), key, entry)


def test_processes_deriving_and_writing_at_once_leave_a_whole_entry(tmp_path):
    """Two processes derive the same law in an empty folder at the same time (each writes the
    module and the entry): both get the same entry and the folder holds a valid one. Then four
    processes write the same entry 200 times each while this one reads it: every read is a
    whole entry (never a partial file), and no temporary file is left."""
    ctx = multiprocessing.get_context("spawn")
    queue = ctx.Queue()
    procs = [ctx.Process(target=_derive_in_a_process, args=(tmp_path, queue)) for _ in range(2)]
    for p in procs:
        p.start()
    results = [queue.get(timeout=600) for _ in procs]
    for p in procs:
        p.join(timeout=60)
        assert p.exitcode == 0
    assert results[0] == results[1]
    key = _lawcache.law_key(LAWS["cap"])
    folder = tmp_path / "kernels"
    entry = _lawcache.read_entry(folder, key)
    assert entry is not None and entry.module == results[0][0]
    writers = [ctx.Process(target=_write_many, args=(str(folder), key, entry, 200))
               for _ in range(4)]
    for p in writers:
        p.start()
    reads = 0
    while any(p.is_alive() for p in writers):
        got = _lawcache.read_entry(folder, key)
        assert got is not None and _bits(got.parameter_values) == _bits(entry.parameter_values)
        reads += 1
    for p in writers:
        p.join()
        assert p.exitcode == 0
    assert reads > 0
    assert sorted(f.name for f in folder.iterdir() if not f.name.startswith("__")) == sorted(
        [entry.module + ".py", _lawcache.entry_path(folder, key).name])


def test_the_cache_folder_follows_numbas_without_its_own(tmp_path, monkeypatch):
    """``$FRICTIONRULES_CACHE_DIR`` first; without it, beside Numba's cache
    (``$NUMBA_CACHE_DIR/frictionrules``); without either, the user's cache folder."""
    monkeypatch.delenv("FRICTIONRULES_CACHE_DIR", raising=False)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    assert _generated.cache_dir() == tmp_path / "numba" / "frictionrules" / "kernels"
    monkeypatch.setenv("FRICTIONRULES_CACHE_DIR", str(tmp_path / "own"))
    assert _generated.cache_dir() == tmp_path / "own" / "kernels"
    monkeypatch.delenv("FRICTIONRULES_CACHE_DIR")
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert _generated.cache_dir() == tmp_path / "xdg" / "frictionrules" / "kernels"
