"""Elastic-plastic contact with hardening and softening (paper §4): the model, the
ellipsoidal cap (4.9), implicit and explicit integration, and a single-contact driver."""

# the laws of §4 live in frictionrules.laws; importable from here too
from ..laws import AreaGrowth, AreaHardening, EllipsoidCap, HardenedLaw, SlipHardening  # noqa: F401
from .driver import DriveResult, Path, drive, read_path
from .model import ContactModel
from .state import ContactState, UpdateResult

__all__ = [
    "ContactModel",
    "ContactState",
    "UpdateResult",
    "drive",
    "DriveResult",
    "Path",
    "read_path",
]
