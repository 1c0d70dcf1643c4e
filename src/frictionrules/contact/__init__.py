"""Elastic-plastic contact with hardening and softening (paper §4): the model, the
ellipsoidal cap (4.9), implicit and explicit integration, and a single-contact driver."""

# the laws of §4 live in frictionrules.laws; importable from here too
from ..laws import AreaGrowth, AreaHardening, EllipsoidCap, HardenedLaw, SlipHardening  # noqa: F401
from .driver import DriveResult, Path, drive, read_path
from .model import ContactModel
from .state import ContactState, UpdateResult

#: The compiled entry of one contact update (Numba), imported on first use: ``contact_update``,
#: the limit check alone ``limit_value``, and the per-thread ``workspace`` / ``Workspace`` of
#: :mod:`frictionrules.contact._return_kernel`; the root of the elliptic return's scalar
#: equation ``ellipse_root`` (:mod:`frictionrules.contact._kernel_special`).
_COMPILED = ("contact_update", "limit_value", "workspace", "Workspace")


def __getattr__(name):
    if name == "ellipse_root":
        from . import _kernel_special
        return _kernel_special.ellipse_root
    if name in _COMPILED:
        from . import _return_kernel
        return getattr(_return_kernel, name)
    if name in ("CompiledLaw", "compiled_law"):
        from . import _generated
        return getattr(_generated, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "ContactModel",
    "ContactState",
    "UpdateResult",
    "drive",
    "DriveResult",
    "Path",
    "read_path",
]
