"""Small result records of the law protocol."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["InverseRelation", "Cone", "ClosedFormReturn"]


@dataclass(frozen=True)
class InverseRelation:
    """Forces on the limit surface that slide in given directions ((1.8), (1.13)).

    Attributes
    ----------
    force : (..., 2)
        Tangential force ``T`` (``inf`` where locked).
    locked : (...) bool
        True where no finite force slides in that direction (self-locking).
    """

    force: np.ndarray
    locked: np.ndarray


@dataclass(frozen=True)
class Cone:
    r"""An elliptic friction cone with a constant dilatancy ratio (the capability ``"cone"``).

    Limit :math:`\sqrt{(T'_1/\mu_x)^2 + (T'_2/\mu_y)^2} \le N`, :math:`T' = R(-\text{angle})T`;
    the tangential slip is normal to the ellipse and the normal slip is
    :math:`v_n = d\,\bar\mu\,|A^T v_t|`, :math:`\bar\mu = \sqrt{\mu_x\mu_y}`,
    :math:`A = R(\text{angle})\,\mathrm{diag}(\mu_x, \mu_y)/\bar\mu` ((1.5): ``d = 0``;
    the dilatant rule (1.6): ``d = 1``).
    """

    mu_x: float
    mu_y: float
    angle: float = 0.0
    dilatancy: float = 0.0


@dataclass(frozen=True)
class ClosedFormReturn:
    """A law's hand-written compiled return mapping: the kernel's name and its parameters.

    The contact integration (:mod:`frictionrules.contact`) runs the named kernel with these
    parameters instead of the generated return mapping.
    """

    kernel: str
    params: tuple
