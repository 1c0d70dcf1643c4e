"""Printer: a :class:`Program` as a Python function for Numba (``math`` functions only)."""

from __future__ import annotations

__all__ = ["python_function"]


def python_function(program, name: str, decorator: str = "") -> str:
    """Source of ``def name(x0, x1, x2, q, p, w)`` writing the program's outputs into ``w``.

    ``q`` and ``p`` are arrays of the internal variables and the parameters; ``w`` the flat
    layout (:func:`~frictionrules.codegen.local_layout`). Slots the program does not compute
    are left untouched.
    """
    from sympy.printing.pycode import PythonCodePrinter

    printer = PythonCodePrinter({"fully_qualified_modules": True, "standard": "python3"})
    lines = [decorator] if decorator else []
    lines.append(f"def {name}(x0, x1, x2, q, p, w):")
    lines += [f"    q{i} = q[{i}]" for i in range(program.nq)]
    lines += [f"    p{i} = p[{i}]" for i in range(program.nparams)]
    lines += [f"    {s} = {printer.doprint(e)}" for s, e in program.temps]
    lines += [f"    w[{k}] = {printer.doprint(e)}" for k, e in program.outputs]
    lines.append("    return 0")
    return "\n".join(lines) + "\n"
