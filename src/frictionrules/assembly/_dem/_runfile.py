r"""The HDF5 run file of a dynamic run: its records as they come, and the engine's state to
resume from, bit for bit.

Layout (``docs/assembly.md``, "Run files"):

* root attributes: ``software``, ``command``, ``parameters`` (JSON, ``method = "dem"``),
  ``sample``, ``status``, and ``engine``: the slot (``a`` or ``b``) holding the state to resume
  from;
* ``/records/000000, ...``: one group per record (0: the consolidated sample): ``stress``,
  ``strain``, ``positions``, ``cell``, the record's numbers as attributes, and its contacts
  (``contacts/grains``, ``shift``, ``frame``, ``force``, ``slip``, ``status``, ``group``,
  ``states/g/...``); the attribute ``complete`` is written last;
* ``/engine/a``, ``/engine/b``: the engine's state (grains, cell, pairs with the contacts'
  histories, stress, meters, and the grains of one pair per contact model) with the record it
  belongs to and the stage (``frictionless``, ``consolidation``, ``shear``).

A record is written after the engine's state of the same moment went into the slot not in use,
and the root's ``engine`` attribute is switched last: an interruption at any point leaves the
file at its last complete record with the state that continues it.

A run with a file keeps in memory the contacts of its last record only: the result's
``contacts`` are a :class:`RecordedContacts` that reads the others from the file when asked
for (at 10⁵ spheres a record's contacts take about 55 MB).
"""

from __future__ import annotations

import operator
from collections.abc import Sequence

import numpy as np

from ...errors import FrictionRulesError
from .._results import ContactSnapshot
from .._runfile import open_h5, read_state, write_states
from ._records import Record
from ._state import METERS, Cell, DemState, Grains, Pairs, new_meters

__all__ = ["DemRunFile", "RecordedContacts"]

_SCALARS = ("time", "steps", "coordination", "coordination_without_rattlers", "sliding_fraction",
            "unbalanced_force", "boundary_work", "dissipation", "damping_loss", "elastic_energy",
            "kinetic_energy")
_SNAPSHOT = ("grains", "shift", "frame", "force", "slip", "status", "group")


class DemRunFile:
    """An open run file of a dynamic run (use :meth:`open`)."""

    def __init__(self, h5, assembly):
        self.h5, self.assembly = h5, assembly

    @classmethod
    def open(cls, path, assembly, options: dict) -> "DemRunFile":
        return cls(open_h5(path, assembly, options, "records"), assembly)

    # ---- writing ----------------------------------------------------------------------------
    def _slot(self) -> str:
        return "b" if self.h5.attrs.get("engine", "") == "a" else "a"

    def _write_engine(self, k: int, state: DemState, dyn, stage: str) -> str:
        slot = self._slot()
        name = f"engine/{slot}"
        if name in self.h5:
            del self.h5[name]
        g = self.h5.create_group(name)
        for part, record in (("grains", state.grains), ("cell", state.cell), ("pairs", state.pairs)):
            for key, value in record._asdict().items():
                g.create_dataset(f"{part}/{key}", data=value)
        g.create_dataset("stress", data=state.stress)
        g.create_dataset("meters", data=state.meters)
        g.create_dataset("group_keys", data=dyn.group_keys(state))
        g.attrs["record"] = int(k)
        g.attrs["stage"] = stage
        g.attrs["complete"] = True
        self.h5.flush()
        return slot

    def save_engine(self, k: int, state: DemState, dyn, stage: str) -> None:
        """The engine's state (of record ``k``; -1 before the first) as the one to resume from."""
        self.h5.attrs["engine"] = self._write_engine(k, state, dyn, stage)
        self.h5.flush()

    def append(self, k: int, record: Record, state: DemState, dyn, stage: str) -> None:
        """Record ``k`` and the engine's state at it."""
        slot = self._write_engine(k, state, dyn, stage)
        name = f"{k:06d}"
        rec = self.h5["records"]
        if name in rec:
            del rec[name]
        g = rec.create_group(name)
        for key in ("stress", "strain", "positions", "cell"):
            g.create_dataset(key, data=getattr(record, key))
        for key in _SCALARS:
            g.attrs[key] = getattr(record, key)
        snap = record.contacts
        for key in _SNAPSHOT:
            g.create_dataset(f"contacts/{key}", data=getattr(snap, key), compression="gzip")
        write_states(g.require_group("contacts"), snap.states)
        g.attrs["complete"] = True
        self.h5.flush()
        self.h5.attrs["engine"] = slot
        self.h5.flush()

    def close(self, status: str) -> None:
        self.h5.attrs["status"] = status
        self.h5.close()

    # ---- reading ----------------------------------------------------------------------------
    def restore(self, dyn):
        """``(stage, state, records)`` to continue from, or None for a new file."""
        slot = self.h5.attrs.get("engine", "")
        if not slot:
            return None
        g = self.h5[f"engine/{slot}"]
        last = int(g.attrs["record"])
        records = [_record(self.h5[f"records/{k:06d}"], k == last) for k in range(last + 1)]
        grains = Grains(**{k: np.asarray(v) for k, v in g["grains"].items()})
        cell = Cell(**{k: np.asarray(v) for k, v in g["cell"].items()})
        pairs = Pairs(**{k: np.asarray(v) for k, v in g["pairs"].items()})
        saved = np.asarray(g["meters"])
        meters = new_meters()  # a file of an older version lacks the newer meters
        for name in saved.dtype.names:
            if name in METERS.names:
                meters[name] = saved[name]
        state = DemState(grains, cell, pairs, np.asarray(g["stress"]), meters)
        dyn.restore_groups(np.asarray(g["group_keys"]))
        return str(g.attrs["stage"]), state, records

    def contacts(self, records: list) -> "RecordedContacts":
        """The contacts of ``records`` (all written to this file, the last one held)."""
        return RecordedContacts(self.h5.filename, len(records), records[-1].contacts)


def _snapshot(c) -> ContactSnapshot:
    states = tuple(read_state(c[f"states/{m}"]) for m in range(len(c["states"])))
    return ContactSnapshot(*(np.asarray(c[key]) for key in _SNAPSHOT[:-1]), states,
                           np.asarray(c["group"]))


def _record(g, contacts: bool) -> Record:
    """A record of the file; its contacts read only when ``contacts`` (else None)."""
    scalars = {key: g.attrs[key] for key in _SCALARS}
    return Record(float(scalars["time"]), int(scalars["steps"]), np.asarray(g["stress"]),
                  np.asarray(g["strain"]),
                  *(float(scalars[key]) for key in _SCALARS[2:]),
                  _snapshot(g["contacts"]) if contacts else None,
                  np.asarray(g["positions"]), np.asarray(g["cell"]))


class RecordedContacts(Sequence):
    """The records' :class:`~frictionrules.assembly.ContactSnapshot` of a dynamic run with a
    run file, read from the file when indexed; the last record's held in memory. A sequence
    like the tuple of a run without a file (``len``, indexing, slicing, iteration)."""

    def __init__(self, path, count: int, last: ContactSnapshot):
        self.path, self._count, self._last = str(path), int(count), last

    def __len__(self) -> int:
        return self._count

    def __getitem__(self, k):
        if isinstance(k, slice):
            return tuple(self[i] for i in range(*k.indices(self._count)))
        k = operator.index(k)
        if k < 0:
            k += self._count
        if not 0 <= k < self._count:
            raise IndexError(f"record {k} of {self._count}")
        if k == self._count - 1:
            return self._last
        import h5py
        try:
            with h5py.File(self.path, "r") as h5:
                return _snapshot(h5[f"records/{k:06d}/contacts"])
        except (OSError, KeyError) as error:
            raise FrictionRulesError(
                f"run_file = {self.path!r} does not hold the contacts of record {k} ({error}); "
                "constraint: the run file of this result, unchanged since the run") from None

    def __repr__(self) -> str:
        return f"RecordedContacts({self.path!r}, {self._count} records)"
