"""Target ``c``: a dependency-free C99 header and source with the law's return mapping.

``<name>_update(params, state_in, increment, state_out, force, tangent)`` integrates one step of
the elastic-plastic contact of :class:`~frictionrules.ContactModel` (elastic law (4.2), sliding
rule (4.3), evolution (4.5), backward Euler, consistent tangent):

- ``params``: ``kt, kn``, then the law's parameters (:attr:`LawSpec.param_names` order);
- ``state_in``, ``state_out``: ``δᵉ (3), δᵖ (3)`` (δn positive on opening), then the internal
  variables q;
- ``increment``: ``(Δδt1, Δδt2, Δδn)``;
- ``force``: ``(T1, T2, N)``, N > 0 in compression;
- ``tangent``: ``d(T1, T2, N)/d(δt1, δt2, δn)`` row-major 3 × 3, or NULL.

It returns 0 (stick: elastic), 1 (slip: plastic), 2 (open) or -1 (no convergence even after
2^10 substeps; ``state_out`` untouched).
"""

from __future__ import annotations

from ._c_template import CORE, UPDATE


def law_functions_c(spec) -> str:
    """Layout constants, the guarded helpers and the law's three local functions in C."""
    from ..codegen import c_function, c_helpers, local_layout, local_program
    layout = local_layout(spec.nq)
    consts = [f"    NQ = {spec.nq}", f"    SIZE = {local_program(spec.form, 'f').size}",
              f"    CLIP = {int(spec.clip)}", f"    HAS_KAPPA = {int(spec.has_kappa)}",
              f"    KAPPA = {spec.kappa}"]
    consts += [f"    OFF_{k.upper()} = {off}" for k, (off, _) in layout.items() if k != "f"]
    prefix = spec.name
    out = ["enum {", ",\n".join(consts), "};", "", c_helpers(prefix)]
    for level in ("f", "first", "full"):
        out.append(c_function(local_program(spec.form, level), f"local_{level}", prefix))
    return "\n".join(out)


def c_sources(spec) -> dict[str, str]:
    """``{file name: text}`` of the header and the source."""
    name, up = spec.name, spec.name.upper()
    head = spec.header(" *", "c")
    nparams = 2 + len(spec.param_names)
    nstate = 6 + spec.nq
    params = ", ".join(("kt", "kn", *spec.param_names))
    state = ", ".join(("de_t1", "de_t2", "de_n", "dp_t1", "dp_t2", "dp_n", *spec.state_names))
    h = ["/*", *head, " */", f"#ifndef {up}_H", f"#define {up}_H", "",
         f"/* params: {params} */", f"#define {up}_NPARAMS {nparams}",
         f"/* state: {state} */", f"#define {up}_NSTATE {nstate}", "",
         "/* One step of prescribed displacement increments (dt1, dt2, dn; dn > 0 opens):",
         "   returns 0 stick, 1 slip, 2 open, -1 no convergence. force = (T1, T2, N), N > 0 in",
         "   compression; tangent = d(T1, T2, N)/d(dt1, dt2, dn) row-major, or NULL. */",
         f"int {name}_update(const double *params, const double *state_in, "
         "const double *increment,",
         "    double *state_out, double *force, double *tangent);", "",
         "/* The state of a virgin contact. */",
         f"void {name}_initial_state(double *state);", "", f"#endif /* {up}_H */", ""]
    initial = "\n    ".join(f"state[{6 + k}] = {v!r};" for k, v in enumerate(spec.initial)) \
        or "(void)state;"
    from .._returnspec import placeholders
    body = (CORE + UPDATE).replace("@NAME_UPPER@", up).replace("@NAME@", name)
    for key, value in placeholders(lambda v: repr(float(v))).items():
        body = body.replace(key, value)
    body = body.replace("@INITIAL@", initial)
    from ._c_structured import structured_c
    body = body.replace("@STRUCTURED@", structured_c(spec))
    c = ["/*", *head, " */", "#include <math.h>", "#include <stddef.h>", f'#include "{name}.h"', "",
         law_functions_c(spec), body.lstrip("\n")]
    return {f"{name}.h": "\n".join(h), f"{name}.c": "\n".join(c)}
