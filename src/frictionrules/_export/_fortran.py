"""Fixed-form Fortran 77 sources of the Abaqus targets: the law's local subroutines, the return
mapping (``_f_return.py``) and the user subroutine of the target (``_f_standard.py``,
``_f_explicit.py``)."""

from __future__ import annotations

from ._f_return import CORE


def prefix(spec) -> str:
    """Prefix of every Fortran name of the law (upper case, at most 20 characters)."""
    return spec.name.upper()


def refit(text: str) -> str:
    """Statements longer than 72 columns (after the prefix went in) broken into continuation
    lines; comments and short lines untouched."""
    from ..codegen import fixed_form
    out = []
    for line in text.split("\n"):
        if len(line) <= 72 or line[:1] in "Cc*!":
            out.append(line)
            continue
        body = line[6:]
        indent = 6 + len(body) - len(body.lstrip())
        parts = fixed_form(body, indent=indent)
        out.append(line[:6] + parts[0][6:])
        out += parts[1:]
    return "\n".join(out)


def parameter_block(spec) -> str:
    """The PARAMETER statements of the layout, repeated in every subroutine."""
    from .._returnspec import APEX, ELASTIC, FAILED, MAX_SUBSTEP_DEPTH, OPEN, PLASTIC
    from ..codegen import fixed_form, local_layout, local_program
    layout = local_layout(spec.nq)
    values = {"NQ": spec.nq, "NQS": max(spec.nq, 1), "M": 4 + spec.nq,
              "NSIZE": local_program(spec.form, "f").size, "ICLIP": int(spec.clip),
              "HASKAP": int(spec.has_kappa), "KAPPA": spec.kappa}
    values |= {f"OFF{k.upper()}": off for k, (off, _) in layout.items() if k != "f"}
    values |= {"KELAS": ELASTIC, "KPLAS": PLASTIC, "KOPEN": OPEN, "KAPEX": APEX, "KFAIL": FAILED,
               "MAXDEP": MAX_SUBSTEP_DEPTH}
    lines = []
    names = list(values)
    for k in range(0, len(names), 5):
        chunk = names[k:k + 5]
        lines += fixed_form("INTEGER " + ", ".join(chunk))
        lines += fixed_form("PARAMETER (" + ", ".join(f"{n} = {values[n]}" for n in chunk) + ")")
    return "\n".join(lines)


def real(value: float) -> str:
    """A double-precision literal that reads back as ``value`` (``0.5D0``, ``1.5D-07``)."""
    text = repr(float(value)).upper()
    return text.replace("E", "D") if "E" in text else text + "D0"


def fill(template: str, spec) -> str:
    """A template with the law's prefix, layout, number of parameters and virgin state in."""
    from .._returnspec import placeholders
    q0 = ", ".join(real(v) for v in spec.initial) or "0.0D0"
    text = (template.replace("@PARAMS@", parameter_block(spec)).replace("@P@", prefix(spec))
            .replace("@NPAR@", str(len(spec.param_names))).replace("@Q0@", q0))
    for key, value in placeholders(real).items():
        text = text.replace(key, value)
    return text


def law_subroutines(spec) -> str:
    """The guarded helpers, the law's three local subroutines and the return mapping."""
    from ..codegen import fortran_helpers, fortran_subroutine, local_program
    p = prefix(spec)
    out = []
    for level, suffix in (("f", "LF"), ("first", "L1"), ("full", "L2")):
        out.append(fortran_subroutine(local_program(spec.form, level), f"{p}{suffix}", p))
    out.append(fortran_helpers(p))
    out.append(fill(CORE, spec))
    return "C " + "-" * 70 + "\n" + "\n".join(out)


def header(spec, target: str, lines: list[str]) -> str:
    """Comment lines (C in column 1) of the header, wrapped at 72 columns."""
    import textwrap
    out = []
    for line in spec.header("C", target) + [f"C {line}".rstrip() for line in lines]:
        out += textwrap.wrap(line, 72, subsequent_indent="C     ") or ["C"]
    return "\n".join(out) + "\n"
