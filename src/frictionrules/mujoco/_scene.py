r"""Which law and which material axis each MuJoCo contact gets: geom names resolved once.

``laws`` maps geom names to friction laws:

* a pair ``("floor", "sled")`` (order-free) is the law of every contact between those geoms;
* a single name ``"floor"`` is the law of every contact of that geom with a geom of no entry
  of its own.

The law of a contact between geoms ``a`` and ``b`` is, in this order: the pair's entry; the
single entry of ``a`` or of ``b`` when exactly one of them has one, or when both have the same
law; ``default``. Two different single entries and no pair entry is an error naming the pair
(give the pair an entry), and so is a contact with no law at all and no ``default``. A number
is isotropic Coulomb ``mu``.

``axes`` maps a geom name to a direction in that geom's own frame (MuJoCo's ``geom_xmat``);
it becomes the law's local direction 1 on the contact plane (:mod:`._assemble`). A contact
between two geoms that both have axes is refused (which body's axes would rule is not
defined).
"""

from __future__ import annotations

import numpy as np

from ..errors import FrictionRulesError, check_finite

__all__ = ["Scene"]


def _geom_id(mujoco, model, name, what: str) -> int:
    if not isinstance(name, str):
        raise FrictionRulesError(f"{what} key {name!r} is not a geom name (a str)")
    gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
    if gid < 0:
        raise FrictionRulesError(f"{what} key {name!r} is not a geom of the model "
                                 "(name it in the XML: <geom name=...>)")
    return int(gid)


def _check_law(law, where: str):
    """A number >= 0 or a law that the many-contact problem accepts; refused here, naming
    the entry, rather than at the first contact that uses it."""
    from ..multicontact import FrictionContactProblem
    if isinstance(law, (bool, np.bool_)):
        raise FrictionRulesError(f"{where} = {law!r} is not a friction law or a coefficient")
    try:
        FrictionContactProblem(np.eye(3), np.zeros(3), [law])
    except FrictionRulesError as exc:
        raise FrictionRulesError(f"{where}: {exc}") from None
    if isinstance(law, (int, float, np.integer, np.floating)):
        from ..laws import Coulomb
        return Coulomb(float(law))   # one object per entry: the problem caches its cone by id
    return law


class Scene:
    """Geom-indexed laws and axes of one model (built once; each step looks contacts up).

    Parameters
    ----------
    model : mujoco.MjModel
    laws : mapping
        Geom name or pair of geom names -> law or number (see the module docstring).
    axes : mapping, optional
        Geom name -> direction ``(3,)`` in the geom's frame.
    default : law or number, optional
        The law of a contact no entry covers.
    """

    def __init__(self, mujoco, model, laws, axes=None, default=None):
        if not hasattr(laws, "items"):
            raise FrictionRulesError(f"laws = {laws!r} is not a mapping of geom names to laws")
        self.ngeom = int(model.ngeom)
        self.pair: dict[int, object] = {}
        self.single: dict[int, object] = {}
        for key, law in laws.items():
            if isinstance(key, tuple):
                if len(key) != 2:
                    raise FrictionRulesError(f"laws key {key!r} violates: a geom name or a pair of names")
                a, b = (_geom_id(mujoco, model, k, "laws") for k in key)
                self.pair[self._key(a, b)] = _check_law(law, f"laws[{key!r}]")
            else:
                self.single[_geom_id(mujoco, model, key, "laws")] = _check_law(law, f"laws[{key!r}]")
        self.default = None if default is None else _check_law(default, "default")
        self.axes = np.zeros((self.ngeom, 3))
        self.has_axis = np.zeros(self.ngeom, dtype=bool)
        for key, direction in (axes or {}).items():
            g = _geom_id(mujoco, model, key, "axes")
            v = check_finite(f"axes[{key!r}]", direction).ravel()
            if v.size != 3 or not np.linalg.norm(v) > 0:
                raise FrictionRulesError(f"axes[{key!r}] = {direction!r} violates: a non-zero 3-vector "
                                         "in the geom's frame")
            self.axes[g] = v / np.linalg.norm(v)
            self.has_axis[g] = True
        self.any_axis = bool(self.has_axis.any())
        self.names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, i) or f"geom {i}"
                      for i in range(self.ngeom)]
        self._cache: dict[int, object] = {}
        self._last_keys, self._last_laws = None, ()
        #: the laws tuple of the last step and its ContactLaws (kept while the contacts' laws
        #: are the same)
        self.problem = None
        from ._assemble import Trees
        self.trees = Trees(model)

    def _key(self, a: int, b: int) -> int:
        return min(a, b) * self.ngeom + max(a, b)

    def _resolve(self, a: int, b: int):
        key = self._key(a, b)
        if key in self.pair:
            return self.pair[key]
        la, lb = self.single.get(a), self.single.get(b)
        if la is not None and lb is not None and la != lb:
            raise FrictionRulesError(f"the contact of geoms {self.names[a]!r} and {self.names[b]!r} has two "
                                     "different single-geom laws; give the pair an entry in laws")
        law = la if la is not None else lb
        if law is None:
            law = self.default
        if law is None:
            raise FrictionRulesError(f"the contact of geoms {self.names[a]!r} and {self.names[b]!r} has no "
                                     "law: add the pair or one of the geoms to laws, or give default")
        return law

    def laws_of(self, geom1: np.ndarray, geom2: np.ndarray) -> tuple:
        """The law of each contact ``(geom1[i], geom2[i])``; the same tuple object as the last
        call's when the contacts' pairs are the same (the laws' reduction is then kept)."""
        keys = np.minimum(geom1, geom2) * self.ngeom + np.maximum(geom1, geom2)
        if self._last_keys is not None and np.array_equal(keys, self._last_keys):
            return self._last_laws
        cache = self._cache
        out = []
        for k, a, b in zip(keys.tolist(), geom1.tolist(), geom2.tolist()):
            law = cache.get(k)
            if law is None:
                law = cache[k] = self._resolve(a, b)
            out.append(law)
        self._last_keys, self._last_laws = keys, tuple(out)
        return self._last_laws

    def axis_owner(self, geom1: np.ndarray, geom2: np.ndarray) -> np.ndarray:
        """Per contact the geom whose axes set its law frame, or -1 (MuJoCo's frame)."""
        h1, h2 = self.has_axis[geom1], self.has_axis[geom2]
        both = h1 & h2
        if both.any():
            i = int(np.flatnonzero(both)[0])
            raise FrictionRulesError(f"the contact of geoms {self.names[geom1[i]]!r} and "
                                     f"{self.names[geom2[i]]!r}: both have axes; give axes to one of them")
        return np.where(h1, geom1, np.where(h2, geom2, -1))
