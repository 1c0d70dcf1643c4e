"""Elastic-plastic contact with hardening and softening (paper §4): the model, the
ellipsoidal cap (4.9), implicit and explicit integration, and a single-contact driver."""

from ..laws import AreaGrowth, AreaHardening, EllipsoidCap, HardenedLaw, SlipHardening
from .driver import DriveResult, Path, drive, read_path
from .model import ContactModel
from .state import ContactState, UpdateResult

__all__ = [
    "ContactModel",
    "ContactState",
    "UpdateResult",
    "SlipHardening",
    "HardenedLaw",
    "EllipsoidCap",
    "AreaHardening",
    "AreaGrowth",
    "drive",
    "DriveResult",
    "Path",
    "read_path",
]
