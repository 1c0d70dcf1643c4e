"""Reading TOML input files (CLI configurations, driver paths) with a clear error."""

from __future__ import annotations


def load_toml(path) -> dict:
    """Parse the TOML file ``path``.

    Raises
    ------
    FrictionRulesError
        When the file is not valid TOML (the message names the file and the parser's reason).
    OSError
        When the file cannot be read.
    """
    import tomllib

    from .errors import FrictionRulesError
    with open(path, "rb") as fh:
        try:
            return tomllib.load(fh)
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise FrictionRulesError(f"{path}: not valid TOML ({exc})") from exc
