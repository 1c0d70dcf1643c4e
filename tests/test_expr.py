"""Safe law expressions: a whitelist parser that builds SymPy objects and never runs the text."""

import builtins
import contextlib
import math
import sys

import pytest
import sympy
from hypothesis import example, given, settings
from hypothesis import strategies as st

from frictionrules.errors import FrictionRulesError
from frictionrules.laws._expr import MAX_DEPTH, MAX_EXPONENT, MAX_LENGTH, parse_expression

T1, T2, N = sympy.symbols("T1 T2 N")
SYMBOLS = {"T1": T1, "T2": T2, "N": N}


def parse(text, symbols=SYMBOLS):
    return parse_expression(text, symbols, name="limit")


class CodeWouldRun(BaseException):
    """Raised by the traps below; a BaseException so that no `except Exception` hides it."""


@contextlib.contextmanager
def no_code_execution(monkeypatch):
    """Trap every way text could become code: eval/exec/compile, imports of modules not yet
    loaded (or of os, subprocess, ...), and SymPy's string parsers (sympify of a str)."""
    loaded = set(sys.modules)
    real_import = builtins.__import__
    forbidden = {"os", "subprocess", "shutil", "posix", "socket", "pty", "importlib"}

    def trap(*args, **kwargs):
        raise CodeWouldRun(f"code execution attempted: {args[:1]!r}")

    def guarded_import(name, globals=None, locals=None, fromlist=(), level=0):
        absolute = name
        if level:  # a relative import inside a package: resolve it against the package
            base = (globals or {}).get("__package__") or ""
            base = base.rsplit(".", level - 1)[0] if level > 1 else base
            absolute = f"{base}.{name}" if name else base
        if absolute.partition(".")[0] in forbidden or absolute not in loaded:
            raise CodeWouldRun(f"import of {absolute!r} attempted")
        return real_import(name, globals, locals, fromlist, level)

    sympify_module = sys.modules["sympy.core.sympify"]
    real_sympify = sympify_module.sympify

    def guarded_sympify(a, *args, **kwargs):
        if isinstance(a, str):
            raise CodeWouldRun(f"sympify of the string {a!r} attempted")
        return real_sympify(a, *args, **kwargs)

    with monkeypatch.context() as m:
        for name in ("eval", "exec", "compile"):
            m.setattr(builtins, name, trap)
        m.setattr(builtins, "__import__", guarded_import)
        m.setattr(sympify_module, "sympify", guarded_sympify)
        m.setattr(sympy, "sympify", guarded_sympify)
        m.setattr(sympy, "parse_expr", trap)
        m.setattr(sys.modules["sympy.parsing.sympy_parser"], "parse_expr", trap)
        yield


@pytest.fixture(scope="module", autouse=True)
def _warm_up():
    # load every SymPy module the parser may touch, before the import trap is armed
    parse("sqrt(T1^2 + T2**2) - 0.3*N + Max(T1, 0) + Min(T1, 1) + atan2(T1, T2) + abs(T1) + exp(-N)"
          " + log(N + 1) + sin(T1) + cos(T1) + tan(T1) + atan(T1) + asin(T1/(1 + T1**2)) + pi + E"
          " + acos(T2/(1 + T2**2)) + sinh(T1) + cosh(T1) + tanh(T1) + sign(T1) + 1/2")


# ---- what is accepted --------------------------------------------------------------------
@pytest.mark.parametrize("text, want", [
    ("sqrt(T1**2 + T2**2) - 0.3*N", sympy.sqrt(T1**2 + T2**2) - sympy.Float("0.3") * N),
    ("sqrt(T1^2 + T2^2) - 0.3*N", sympy.sqrt(T1**2 + T2**2) - sympy.Float("0.3") * N),
    ("-T1**2", -(T1**2)),                       # Python precedence: -(T1**2)
    ("2**-1", sympy.Rational(1, 2)),
    ("2**3**2", sympy.Integer(512)),            # right-associative
    ("1/2*T1", T1 / 2),                         # integers and their quotients stay exact
    ("(T1 + T2) * N", (T1 + T2) * N),
    ("+T1 - -T2", T1 + T2),
    ("Max(T1, T2, 0) + min(T1, N)", sympy.Max(T1, T2, 0) + sympy.Min(T1, N)),
    ("atan2(T2, T1)", sympy.atan2(T2, T1)),
    ("abs(T1) + Abs(T2)", sympy.Abs(T1) + sympy.Abs(T2)),
    (".5e-3 * N + 1.", sympy.Float("0.0005") * N + sympy.Float("1.")),
    ("pi * E * T1", sympy.pi * sympy.E * T1),
    ("exp(-N) * log(1 + N)", sympy.exp(-N) * sympy.log(1 + N)),
])
def test_accepted_expressions(text, want):
    got = parse(text)
    assert got == want
    assert isinstance(got, sympy.Expr)


def test_extra_symbols_take_precedence_over_constants():
    mu, E = sympy.symbols("mu E")
    assert parse("mu*N + E", {**SYMBOLS, "mu": mu, "E": E}) == mu * N + E
    with pytest.raises(FrictionRulesError, match="unknown name 'mu' at position 0"):
        parse("mu*N")


# ---- what is refused, and how it is reported ---------------------------------------------
INJECTIONS = [
    ("__import__('os').system('touch {canary}')", "'"),
    ("__import__", "__import__"),
    ("T1.__class__.__mro__", "."),
    ("().__class__.__bases__[0].__subclasses__()", "."),
    ("lambda: __import__('os')", ":"),
    ("T1[0]", "["),
    ("__builtins__", "__builtins__"),
    ("foo(T1)", "foo"),
    ("eval(T1)", "eval"),
    ("exec(T1)", "exec"),
    ("open(T1)", "open"),
    ("getattr(T1, T2)", "getattr"),
    ("Symbol(T1)", "Symbol"),
    ("T1(2)", "T1"),
    ("2 T1", "T1"),
    ("T1; import os", ";"),
    ("T1 if N else T2", "if"),
    ("T1 == T2", "="),
    ("[T1 for T1 in T2]", "["),
    ('"T1"', '"'),
    ("1j*T1", "j"),
    ("0x10", "x10"),
    ("T1 @ T2", "@"),
    ("T1 # comment", "#"),
]


@pytest.mark.parametrize("text, token", INJECTIONS)
def test_injection_strings_are_refused_and_never_run(text, token, tmp_path, monkeypatch):
    canary = tmp_path / "pwned"
    text = text.format(canary=canary)
    with no_code_execution(monkeypatch), pytest.raises(FrictionRulesError) as err:
        parse(text)
    msg = str(err.value)
    assert msg.startswith("limit = ") and repr(token) in msg and f"at position {text.index(token)}" in msg
    assert len(msg.splitlines()) == 1
    assert not canary.exists()


@pytest.mark.parametrize("text, problem", [
    ("", "is empty"),
    ("   ", "is empty"),
    ("(T1", "ends too early"),
    ("T1 +", "ends too early"),
    ("T1)", "unexpected token ')'"),
    ("sqrt", "function without arguments"),
    ("sqrt(T1, T2)", "2 argument(s)"),
    ("atan2(T1)", "1 argument(s)"),
    ("1/0", "no finite real value"),
    ("log(0)", "no finite real value"),
    ("sqrt(-1)", "no finite real value"),
    ("(-8)**(1/3)", "no finite real value"),
    ("exp(1000)", "no finite real value"),
    ("10**100 * 10**100 * 10**100 * 10**100", "no finite real value"),
    ("1e400", "double-precision range"),
    ("T1/0", "infinite, undefined or complex"),
    ("1/(T1 - T1)", "infinite, undefined or complex"),
    ("9**9**9", "|exponent| <= 100"),
    ("T1**101", "|exponent| <= 100"),
    ("(T1**100)**2", "|exponent| <= 100"),
    ("T1**60 * T1**60", "|exponent| <= 100"),
    ("2" + "**2" * 60, "|exponent| <= 100"),
])
def test_malformed_and_unbounded_expressions(text, problem):
    with pytest.raises(FrictionRulesError, match="^limit = ") as err:
        parse(text)
    assert problem in str(err.value)


def test_bounds_on_length_and_depth():
    assert parse("(" * MAX_DEPTH + "T1" + ")" * MAX_DEPTH) == T1
    with pytest.raises(FrictionRulesError, match=f"deeper than {MAX_DEPTH}"):
        parse("(" * (MAX_DEPTH + 1) + "T1" + ")" * (MAX_DEPTH + 1))
    with pytest.raises(FrictionRulesError, match=f"deeper than {MAX_DEPTH}"):
        parse("sin(" * (MAX_DEPTH + 1) + "T1" + ")" * (MAX_DEPTH + 1))
    with pytest.raises(FrictionRulesError, match=f"deeper than {MAX_DEPTH}"):
        parse("-" * (MAX_DEPTH + 1) + "T1")
    long = "+".join(["T1"] * (MAX_LENGTH // 2))
    with pytest.raises(FrictionRulesError, match=f"at most {MAX_LENGTH}"):
        parse(long)
    assert parse(f"T1**{MAX_EXPONENT}") == T1**MAX_EXPONENT
    with pytest.raises(FrictionRulesError, match="not a string"):
        parse_expression(T1, SYMBOLS, name="limit")
    with pytest.raises(FrictionRulesError, match="symbol name"):
        parse_expression("x", {"sqrt": T1}, name="limit")


# ---- hypothesis: no text ever runs, valid texts round-trip ---------------------------------
FRAGMENTS = ["__import__", "(", ")", "'os'", "\"", ".", "system", "eval", "exec", "lambda", ":",
             "[", "]", "{", "}", "T1", "T2", "N", "2", "0.5", "1e999", "**", "^", "*", "/", "+",
             "-", ",", " ", "sqrt", "Max", "atan2", "log", "exp", "getattr", "__class__",
             "__subclasses__", "open", "globals", ";", "\n", "#", "=", "@", "0x1", "1j", "\\",
             "`", "%", "&", "|", "~", "<", "!", "if", "else", "for", "in", "pi", "E", "é", "\x00"]


@settings(max_examples=300)
@given(st.one_of(st.lists(st.sampled_from(FRAGMENTS), max_size=25).map("".join),
                 st.text(max_size=40)))
@example("__import__('os').system('echo PWNED')")
@example("(lambda: 0)()")
def test_no_text_runs_code(text):
    with pytest.MonkeyPatch.context() as mp, no_code_execution(mp):
        try:
            out = parse(text)
        except FrictionRulesError as err:
            msg = str(err)
            assert msg.startswith("limit") and "\n" not in msg
        else:
            assert isinstance(out, sympy.Expr)
            assert out.free_symbols <= {T1, T2, N}


LEAVES = st.one_of(
    st.sampled_from(["T1", "T2", "N"]).map(lambda s: (s, SYMBOLS[s])),
    st.integers(0, 20).map(lambda i: (str(i), sympy.Integer(i))),
    st.sampled_from(["0.5", "0.3", "2.5e-1", "1.", ".75"]).map(lambda t: (t, sympy.Float(t))),
)
TEMPLATES = {  # function of children -> (text, the SymPy expression built directly)
    "add": lambda a, b: (f"({a[0]}) + ({b[0]})", a[1] + b[1]),
    "sub": lambda a, b: (f"{a[0]} - ({b[0]})", a[1] - b[1]),
    "mul": lambda a, b: (f"({a[0]})*({b[0]})", a[1] * b[1]),
    "div": lambda a, b: (f"({a[0]}) / (({b[0]})^2 + 1)", a[1] / (b[1]**2 + 1)),
    "neg": lambda a, b: (f"-({a[0]})", -a[1]),
    "pow": lambda a, b: (f"({a[0]})**2", a[1]**2),
    "sqrt": lambda a, b: (f"sqrt(({a[0]})**2 + 1)", sympy.sqrt(a[1]**2 + 1)),
    "atan": lambda a, b: (f"atan({a[0]})", sympy.atan(a[1])),
    "sin": lambda a, b: (f"sin({a[0]})", sympy.sin(a[1])),
    "abs": lambda a, b: (f"abs({a[0]})", sympy.Abs(a[1])),
    "max": lambda a, b: (f"Max({a[0]}, {b[0]})", sympy.Max(a[1], b[1])),
    "atan2": lambda a, b: (f"atan2({a[0]}, ({b[0]})**2 + 1)", sympy.atan2(a[1], b[1]**2 + 1)),
}
TREES = st.recursive(LEAVES, lambda kids: st.tuples(st.sampled_from(sorted(TEMPLATES)), kids, kids)
                     .map(lambda t: TEMPLATES[t[0]](t[1], t[2])), max_leaves=10)


def _close(a, b) -> bool:
    points = [{T1: 0.3, T2: -0.7, N: 1.3}, {T1: -2.0, T2: 0.1, N: 0.4}]
    for p in points:
        x, y = complex(a.evalf(subs=p)), complex(b.evalf(subs=p))
        if not (math.isclose(x.real, y.real, rel_tol=1e-9, abs_tol=1e-9) and abs(x.imag - y.imag) < 1e-9):
            return False
    return True


@settings(max_examples=100)
@given(TREES)
def test_valid_expressions_round_trip(tree):
    text, want = tree
    try:
        got = parse(text)
    except FrictionRulesError as err:    # only the numeric bounds may refuse a valid tree
        assert "finite real value" in str(err) or "|exponent|" in str(err)
        return
    assert got == want
    assert _close(parse(str(got)), got)     # SymPy's printed form parses back to the same law


def test_the_traps_catch_what_the_old_parser_did(monkeypatch):
    """The traps above are not vacuous: SymPy's string parser and eval trip them."""
    for attempt in (lambda: sympy.sympify("T1 + 1"), lambda: eval("1"),
                    lambda: __import__("subprocess"),
                    lambda: sys.modules["sympy.parsing.sympy_parser"].parse_expr("T1")):
        with no_code_execution(monkeypatch), pytest.raises(CodeWouldRun):
            attempt()
