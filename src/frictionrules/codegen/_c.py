"""Printer: a :class:`Program` as a C99 function (``<math.h>`` only)."""

from __future__ import annotations

__all__ = ["c_function", "c_helpers", "used_inputs", "c_block"]


def guarded(expr, prefix: str):
    """``expr`` with every negative power ``x**(-a)`` written ``<prefix>_inv(x**a)`` and every
    ``sign(x)`` ``<prefix>_sgn(x)`` (functions the printed file defines): no division by zero.

    The guarded reciprocal is 0 where ``|x| <= 1e-300``, so the derivatives of ``|T|`` at the
    apex of a cone come out as the minimal-norm subgradient 0, as the compiled return mapping
    takes them.
    """
    import sympy

    inv, sgn = sympy.Function(f"{prefix}_inv"), sympy.Function(f"{prefix}_sgn")
    expr = sympy.sympify(expr).replace(lambda e: e.is_Pow and e.exp.is_number and e.exp.is_negative,
                                       lambda e: inv(e.base ** (-e.exp)))
    return expr.replace(sympy.sign, sgn)


def _printer(prefix: str):
    from sympy.printing.c import C99CodePrinter

    names = {f"{prefix}_inv": f"{prefix}_inv", f"{prefix}_sgn": f"{prefix}_sgn"}
    return C99CodePrinter({"user_functions": names})


def c_helpers(prefix: str) -> str:
    """The guarded reciprocal and sign the printed functions call (static, one per file)."""
    return (f"static inline double {prefix}_inv(double x)\n{{\n"
            "    return fabs(x) > 1e-300 ? 1.0 / x : 0.0;\n}\n\n"
            f"static inline double {prefix}_sgn(double x)\n{{\n"
            "    return (double)((x > 0.0) - (x < 0.0));\n}\n")


def used_inputs(program) -> set:
    """Names of the inputs (``x0``, ``q1``, ``p2``, ...) the program reads."""
    names = set()
    for _, e in (*program.temps, *program.outputs):
        names |= {str(s) for s in e.free_symbols}
    return {n for n in names if n[0] in "xqp" and n[1:].isdigit()}


def c_function(program, name: str, prefix: str) -> str:
    """Source of ``static void name(x0, x1, x2, q, p, w)`` writing the program's outputs into
    ``w`` (the flat layout of :func:`~frictionrules.codegen.local_layout`).

    ``q`` and ``p`` are the internal variables and the parameters. Reciprocals and signs call
    the helpers of :func:`c_helpers` with the same ``prefix``. Warning-free under
    ``-Wall -Wextra``: inputs the program does not read are marked unused.
    """
    printer = _printer(prefix)
    used = used_inputs(program)
    lines = [f"static void {name}(double x0, double x1, double x2, const double *q, "
             "const double *p, double *w)", "{"]
    lines += [f"    (void){x};" for x in ("x0", "x1", "x2") if x not in used]
    qs = [i for i in range(program.nq) if f"q{i}" in used]
    ps = [i for i in range(program.nparams) if f"p{i}" in used]
    lines += ["    (void)q;"] if not qs else []
    lines += ["    (void)p;"] if not ps else []
    lines += [f"    const double q{i} = q[{i}];" for i in qs]
    lines += [f"    const double p{i} = p[{i}];" for i in ps]
    lines += [f"    const double {s} = {printer.doprint(guarded(e, prefix))};" for s, e in program.temps]
    lines += [f"    w[{k}] = {printer.doprint(guarded(e, prefix))};" for k, e in program.outputs]
    lines.append("}")
    return "\n".join(lines) + "\n"


def c_block(program, indent: str, prefix: str, declare: str = "const double") -> list[str]:
    """Lines of C declaring a piece's temporaries and named outputs
    (:func:`~frictionrules.codegen.step_programs`: ``name = expression``), each
    ``declare name = ...;``, reciprocals and signs guarded as in :func:`c_function`; every
    output is then marked used (a piece may compute more than a caller reads)."""
    printer = _printer(prefix)
    lines = [f"{indent}const double {s} = {printer.doprint(guarded(e, prefix))};"
             for s, e in program.temps]
    lines += [f"{indent}{declare} {n} = {printer.doprint(guarded(e, prefix))};"
              for n, e in program.outputs]
    lines += [f"{indent}(void){n};" for n, _ in program.outputs]
    return lines
