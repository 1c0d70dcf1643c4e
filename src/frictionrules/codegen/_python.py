"""Printer: a :class:`Program` as a Python function for Numba (``math`` functions only)."""

from __future__ import annotations

__all__ = ["python_function", "parameter_temps", "python_block"]


def parameter_temps(program) -> tuple:
    """The program's common subexpressions that depend on the parameters only, in order:
    ``(symbol, expression)`` pairs, each in the parameters ``p0, p1, ...`` and the earlier
    such subexpressions (e.g. ``sin(angle)``, ``1/mu_x**2``): computed once per law, not once
    per contact."""
    params = {f"p{i}" for i in range(program.nparams)}
    known, out = set(), []
    for sym, expr in program.temps:
        names = {str(s) for s in expr.free_symbols}
        if names <= params | known:
            known.add(str(sym))
            out.append((sym, expr))
    return tuple(out)


def _printer():
    """SymPy's Python printer, with a power to a half-integer exponent written through
    ``math.sqrt`` (``x**(3/2)`` is ``x*math.sqrt(x)``, not a call of ``pow``)."""
    from sympy.printing.pycode import PythonCodePrinter

    class Printer(PythonCodePrinter):
        def _print_Pow(self, expr, rational=False):
            e = expr.exp
            if e.is_Rational and e.q == 2 and abs(e.p) > 1:
                k = (abs(e.p) - 1) // 2
                base = self.parenthesize(expr.base, 100) + ("" if k == 1 else f"**{k}")
                whole = f"{base}*math.sqrt({self._print(expr.base)})"
                return f"({whole})" if e.p > 0 else f"(1/({whole}))"
            return super()._print_Pow(expr, rational=rational)

    return Printer({"fully_qualified_modules": True, "standard": "python3"})


def python_function(program, name: str, decorator: str = "", finite_derivatives: bool = False,
                    hoisted_offset: int | None = None) -> str:
    """Source of ``def name(x0, x1, x2, q, p, w)`` writing the program's outputs into ``w``.

    ``q`` and ``p`` hold the internal variables and the parameters, ``w`` the flat layout
    (:func:`~frictionrules.codegen.local_layout`): arrays, or pointers to their data (a Numba
    ``cfunc``). Slots the program does not compute are left untouched. With
    ``finite_derivatives``, every slot but f is written as 0 where its value is not finite (the
    minimal-norm subgradient at a kink such as the apex of a cone, where the symbolic
    derivative is 0/0); ``v - v == 0`` holds exactly for finite ``v`` only. With
    ``hoisted_offset``, the :func:`parameter_temps` are read from ``p[hoisted_offset + k]``
    instead of being recomputed (the caller appends their values to the parameters).
    """
    printer = _printer()
    lines = [decorator] if decorator else []
    lines.append(f"def {name}(x0, x1, x2, q, p, w):")
    lines += [f"    q{i} = q[{i}]" for i in range(program.nq)]
    lines += [f"    p{i} = p[{i}]" for i in range(program.nparams)]
    hoisted = {sym: k for k, (sym, _) in enumerate(parameter_temps(program))} \
        if hoisted_offset is not None else {}
    for sym, expr in program.temps:
        if sym in hoisted:
            lines.append(f"    {sym} = p[{hoisted_offset + hoisted[sym]}]")
        else:
            lines.append(f"    {sym} = {printer.doprint(expr)}")
    for k, e in program.outputs:
        value = printer.doprint(e)
        if finite_derivatives and k > 0 and not e.is_number:
            lines.append(f"    v = {value}")
            value = "v if v - v == 0.0 else 0.0"
        lines.append(f"    w[{k}] = {value}")
    lines.append("    return 0")
    return "\n".join(lines) + "\n"


def python_block(program, indent: str, hoisted: dict, param: str = "p[{}]") -> list[str]:
    """Lines assigning a piece's temporaries and named outputs. ``hoisted`` maps parameter-only
    temporaries to their index among the parameter values (read as ``param.format(index)``)."""
    printer = _printer()
    lines = []
    for sym, expr in program.temps:
        value = param.format(hoisted[sym]) if sym in hoisted else printer.doprint(expr)
        lines.append(f"{indent}{sym} = {value}")
    lines += [f"{indent}{name} = {printer.doprint(expr)}" for name, expr in program.outputs]
    return lines
