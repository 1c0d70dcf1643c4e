"""Printer: a :class:`Program` as a Python function for Numba (``math`` functions only)."""

from __future__ import annotations

__all__ = ["python_function"]


def python_function(program, name: str, decorator: str = "", finite_derivatives: bool = False) -> str:
    """Source of ``def name(x0, x1, x2, q, p, w)`` writing the program's outputs into ``w``.

    ``q`` and ``p`` hold the internal variables and the parameters, ``w`` the flat layout
    (:func:`~frictionrules.codegen.local_layout`): arrays, or pointers to their data (a Numba
    ``cfunc``). Slots the program does not compute are left untouched. With
    ``finite_derivatives``, every slot but f is written as 0 where its value is not finite (the
    minimal-norm subgradient at a kink such as the apex of a cone, where the symbolic
    derivative is 0/0); ``v - v == 0`` holds exactly for finite ``v`` only.
    """
    from sympy.printing.pycode import PythonCodePrinter

    printer = PythonCodePrinter({"fully_qualified_modules": True, "standard": "python3"})
    lines = [decorator] if decorator else []
    lines.append(f"def {name}(x0, x1, x2, q, p, w):")
    lines += [f"    q{i} = q[{i}]" for i in range(program.nq)]
    lines += [f"    p{i} = p[{i}]" for i in range(program.nparams)]
    lines += [f"    {s} = {printer.doprint(e)}" for s, e in program.temps]
    for k, e in program.outputs:
        value = printer.doprint(e)
        if finite_derivatives and k > 0 and not e.is_number:
            lines.append(f"    v = {value}")
            value = "v if v - v == 0.0 else 0.0"
        lines.append(f"    w[{k}] = {value}")
    lines.append("    return 0")
    return "\n".join(lines) + "\n"
