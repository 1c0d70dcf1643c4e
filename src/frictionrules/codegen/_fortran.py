"""Printer: a :class:`Program` as a fixed-form Fortran 77 subroutine (72 columns)."""

from __future__ import annotations

import re

from ._c import guarded, used_inputs

__all__ = ["fortran_subroutine", "fortran_helpers", "fixed_form"]

#: Tokens a statement may be broken between: numbers (``1.5d-3``), names, anything else.
_TOKEN = re.compile(r"\d+\.?\d*(?:[dDeE][+-]?\d+)?|\.\d+(?:[dDeE][+-]?\d+)?|\w+|\s+|.")


def fixed_form(statement: str, indent: int = 6) -> list[str]:
    """A statement as fixed-form lines: text in columns 7-72, continuation lines marked by
    ``&`` in column 6 (never broken inside a name or a number)."""
    first = " " * indent
    lines, cur = [], first
    for tok in _TOKEN.findall(statement.strip()):
        if len(cur) + len(tok) > 72:
            lines.append(cur.rstrip())
            cur = "     &" + " " * (indent - 6)
            tok = tok.lstrip()
        cur += tok
    lines.append(cur.rstrip())
    return lines


def _printer(prefix: str):
    from sympy.printing.fortran import FCodePrinter

    names = {f"{prefix}_inv": f"{prefix}IV", f"{prefix}_sgn": f"{prefix}SG"}
    return FCodePrinter({"source_format": "free", "standard": 77, "user_functions": names})


def _expression(printer, expr) -> str:
    """One expression on one line (the printer's own free-form wrapping undone: statements
    are broken by :func:`fixed_form`)."""
    text = printer.doprint(expr)
    return re.sub(r"\s*&\s*\n\s*&?\s*", " ", text).strip()


def fortran_helpers(prefix: str) -> str:
    """The guarded reciprocal ``<prefix>IV`` and sign ``<prefix>SG`` the printed subroutines
    call (fixed form)."""
    return "\n".join([
        f"      DOUBLE PRECISION FUNCTION {prefix}IV(X)",
        "      IMPLICIT NONE",
        "      DOUBLE PRECISION X",
        f"      {prefix}IV = 0.0D0",
        f"      IF (ABS(X) .GT. 1.0D-300) {prefix}IV = 1.0D0/X",
        "      RETURN",
        "      END",
        "",
        f"      DOUBLE PRECISION FUNCTION {prefix}SG(X)",
        "      IMPLICIT NONE",
        "      DOUBLE PRECISION X",
        f"      {prefix}SG = 0.0D0",
        f"      IF (X .GT. 0.0D0) {prefix}SG = 1.0D0",
        f"      IF (X .LT. 0.0D0) {prefix}SG = -1.0D0",
        "      RETURN",
        "      END",
    ]) + "\n"


def fortran_subroutine(program, name: str, prefix: str) -> str:
    """Source of ``SUBROUTINE name(X0, X1, X2, Q, P, W)`` writing the program's outputs into
    ``W`` (the flat layout of :func:`~frictionrules.codegen.local_layout`, 1-based).

    Fixed form, ``IMPLICIT NONE``, double precision; reciprocals and signs call the functions
    of :func:`fortran_helpers` with the same ``prefix``. Inputs the program does not read are
    referenced once (``-Wall`` clean).
    """
    printer = _printer(prefix)
    used = used_inputs(program)
    temps = [str(s) for s, _ in program.temps]
    nq = max(program.nq, 1)
    out = [f"      SUBROUTINE {name}(X0, X1, X2, Q, P, W)", "      IMPLICIT NONE",
           "      DOUBLE PRECISION X0, X1, X2",
           f"      DOUBLE PRECISION Q({nq}), P({max(program.nparams, 1)}), W(*)"]
    out += [f"      DOUBLE PRECISION {prefix}IV, {prefix}SG",
            f"      EXTERNAL {prefix}IV, {prefix}SG"]
    locals_ = ([f"Q{i}" for i in range(program.nq) if f"q{i}" in used]
               + [f"P{i}" for i in range(program.nparams) if f"p{i}" in used] + temps)
    for k in range(0, len(locals_), 6):
        out += fixed_form("DOUBLE PRECISION " + ", ".join(locals_[k:k + 6]).upper())
    out += [f"      Q{i} = Q({i + 1})" for i in range(program.nq) if f"q{i}" in used]
    out += [f"      P{i} = P({i + 1})" for i in range(program.nparams) if f"p{i}" in used]
    unused = [x.upper() for x in ("x0", "x1", "x2") if x not in used]
    if not any(q.startswith("q") for q in used):
        unused.append("Q(1)")
    if not any(p.startswith("p") for p in used):
        unused.append("P(1)")
    if unused:  # referenced once, so that -Wall has nothing to say
        out += fixed_form(f"IF (.FALSE.) W(1) = {' + '.join(unused)}")
    for s, e in program.temps:
        out += fixed_form(f"{str(s).upper()} = {_expression(printer, guarded(e, prefix))}")
    for k, e in program.outputs:
        out += fixed_form(f"W({k + 1}) = {_expression(printer, guarded(e, prefix))}")
    out += ["      RETURN", "      END"]
    return "\n".join(out) + "\n"
