"""The HDF5 run file of an assembly test: written increment by increment, read to resume.

Layout (``docs/assembly.md``, "Run files"):

* root attributes: ``software``, ``command``, ``parameters`` (JSON: the loading options),
  ``sample`` (JSON: grains, radii checksum), ``status`` (``running`` or how the run ended);
* ``/increments/000000, 000001, ...``: one group per finished increment (0: the consolidated
  sample) with ``positions``, ``cell``, ``stress``, ``strain`` (compression positive),
  ``work`` (contact work, boundary work), the contacts ``i``, ``j``, ``shift``, ``group``,
  ``frames``, ``force``, ``status`` and, per contact model ``g``, ``states/g/elastic``,
  ``plastic``, ``kappa``, ``beta``, ``internal`` (with the attribute ``names``). The group's
  attribute ``complete`` is written last: a group without it (an interrupted write) is ignored
  on resume, so an interruption loses no finished increment.
"""

from __future__ import annotations

import json

import numpy as np

from ..contact import ContactState
from ..errors import FrictionRulesError
from ..laws import LawState
from ._contacts import ContactSet
from ._results import SampleState

__all__ = ["RunFile", "open_h5", "write_states", "read_state"]


def _sample_key(assembly) -> dict:
    return {"grains": int(assembly.size), "dim": int(assembly.dim),
            "radii_sum": float(np.sum(assembly.radii)),
            "positions_sum": float(np.sum(assembly.positions)),
            "cell": np.asarray(assembly.cell).round(12).tolist(),
            "model": repr(assembly.model)}


def open_h5(path, assembly, options: dict, group: str):
    """The HDF5 run file of a run of ``assembly`` with ``options`` (JSON): a new file with
    its provenance and an empty ``group``, or the same run's file to resume (another run's
    file is refused); its ``status`` set to "running"."""
    from .._optional import require
    from .._output import check_output, command_line
    h5py = require("h5py", purpose="assembly run files")
    path = check_output(path, (".h5", ".hdf5"), name="run_file")
    parameters = json.dumps(options, sort_keys=True)
    sample = json.dumps(_sample_key(assembly), sort_keys=True)
    if path.exists():
        h5 = h5py.File(path, "a")
        if h5.attrs.get("parameters") != parameters or h5.attrs.get("sample") != sample:
            h5.close()
            raise FrictionRulesError(
                f"run_file = {str(path)!r} holds another run (other sample or loading); "
                "constraint: the same assembly and options to resume, or a new file")
    else:
        h5 = h5py.File(path, "w")
        from .._version import __version__
        h5.attrs["software"] = f"frictionrules {__version__}"
        h5.attrs["command"] = command_line()
        h5.attrs["parameters"] = parameters
        h5.attrs["sample"] = sample
        h5.create_group(group)
    h5.attrs["status"] = "running"
    h5.flush()
    return h5


def write_states(g, states) -> None:
    """The contact models' batches of contact states into ``g/states/0, 1, ...``."""
    for m, s in enumerate(states):
        sg = g.create_group(f"states/{m}")
        for key in ("elastic", "plastic", "kappa", "beta"):
            sg.create_dataset(key, data=np.asarray(getattr(s, key)))
        sg.create_dataset("internal", data=s.internal.values)
        sg.attrs["names"] = json.dumps(list(s.internal.names))


def read_state(sg) -> ContactState:
    """A batch of contact states written by :func:`write_states`."""
    names = tuple(json.loads(sg.attrs["names"]))
    return ContactState(np.asarray(sg["elastic"]), np.asarray(sg["plastic"]),
                        np.asarray(sg["kappa"]), np.asarray(sg["beta"]),
                        LawState(names, np.asarray(sg["internal"])))


class RunFile:
    """An open run file (use :meth:`open`)."""

    def __init__(self, h5, assembly):
        self.h5, self.assembly = h5, assembly

    @classmethod
    def open(cls, path, assembly, options: dict) -> "RunFile":
        return cls(open_h5(path, assembly, options, "increments"), assembly)

    # ---- writing ----------------------------------------------------------------------------
    def append(self, k: int, state: SampleState, works, ok: bool) -> None:
        name = f"{k:06d}"
        inc = self.h5["increments"]
        if name in inc:
            del inc[name]
        g = inc.create_group(name)
        c = state.contacts
        for key, value in (("positions", state.positions), ("cell", state.cell),
                           ("stress", state.stress), ("strain", state.strain),
                           ("work", np.asarray(works, dtype=float)), ("i", c.i), ("j", c.j),
                           ("shift", c.shift), ("group", c.group), ("frames", c.frames),
                           ("force", c.force if c.force is not None else np.zeros((c.size, 3))),
                           ("status", c.status if c.status is not None else np.zeros(c.size, int))):
            g.create_dataset(key, data=np.asarray(value))
        write_states(g, c.states)
        g.attrs["converged"] = bool(ok)
        g.attrs["complete"] = True
        self.h5.flush()

    def close(self, status: str) -> None:
        self.h5.attrs["status"] = status
        self.h5.close()

    # ---- reading ----------------------------------------------------------------------------
    def rows(self) -> list:
        """The finished increments as ``(state, works, converged)`` rows."""
        inc = self.h5["increments"]
        rows = []
        for k, name in enumerate(sorted(inc)):
            g = inc[name]
            if name != f"{k:06d}" or not g.attrs.get("complete", False):
                break
            rows.append(self._row(g))
        return rows

    def _row(self, g):
        a = self.assembly
        i, j = np.asarray(g["i"]), np.asarray(g["j"])
        group = np.asarray(g["group"])
        states, models = [], []
        for m in range(len(g["states"])):
            states.append(read_state(g[f"states/{m}"]))
            members = np.flatnonzero(group == m)
            models.append(a.model_of(i[members[0]], j[members[0]]) if len(members) else a.model_of(0, 0))
        contacts = ContactSet(i, j, np.asarray(g["shift"]), group, tuple(models), tuple(states),
                              np.asarray(g["frames"]), np.asarray(g["force"]), np.asarray(g["status"]))
        state = SampleState(np.asarray(g["positions"]), np.asarray(g["cell"]), contacts,
                            np.asarray(g["stress"]), np.asarray(g["strain"]))
        w = np.asarray(g["work"])
        return state, (float(w[0]), float(w[1])), bool(g.attrs["converged"])

