"""Elastic-plastic contact with hardening and softening (paper §4): the model, the
ellipsoidal cap (4.9), implicit and explicit integration, and a single-contact driver."""

from .cap import AreaGrowth, AreaHardening, EllipsoidCap
from .driver import DriveResult, Path, drive, read_path
from .model import ContactModel, ContactState, SlipHardening, UpdateResult

__all__ = [
    "ContactModel",
    "ContactState",
    "UpdateResult",
    "SlipHardening",
    "EllipsoidCap",
    "AreaHardening",
    "AreaGrowth",
    "drive",
    "DriveResult",
    "Path",
    "read_path",
]
