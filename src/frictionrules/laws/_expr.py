r"""Safe parsing of law expressions written as text (``"sqrt(T1**2 + T2**2) - mu*N"``).

The text is tokenized and parsed here, by a small recursive-descent parser over a whitelist,
and the SymPy expression is built directly from SymPy objects. Nothing of the text is ever
handed to ``eval``, ``exec``, :func:`sympy.sympify` or :func:`sympy.parse_expr`, so a law read
from a shared file or a web form cannot run code.

Grammar (Python's precedence; ``^`` is a synonym of ``**``, as in most papers — in Python it
would be a bitwise XOR)::

    expr   := term (("+" | "-") term)*
    term   := unary (("*" | "/") unary)*
    unary  := ("+" | "-") unary | power
    power  := atom (("**" | "^") unary)?          right-associative: 2**3**2 = 2**9
    atom   := NUMBER | NAME | FUNCTION "(" expr ("," expr)* ")" | "(" expr ")"

``-T1**2`` is ``-(T1**2)`` and ``2**-1`` is ``1/2``, as in Python. There is no implicit
multiplication (``2 T1`` and ``2T1`` are errors). ``NUMBER`` is a decimal literal (``3``,
``0.5``, ``.5``, ``1e-3``); integers and their quotients stay exact (``1/2`` is the rational
one half), decimal literals become floats. ``NAME`` is one of the symbols passed in, then
``pi`` or ``E`` (Euler's number); a symbol of the same name takes precedence over the constant.

Bounds, so that no string can hang the process: at most :data:`MAX_LENGTH` characters and
:data:`MAX_DEPTH` levels of nesting; a numeric exponent at most :data:`MAX_EXPONENT` in
magnitude; every constant sub-expression (``10**300 * 10**300``, ``1/0``, ``sqrt(-1)``,
``log(0)``) must be a finite real number in double precision.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass

from ..errors import FrictionRulesError

__all__ = ["FUNCTIONS", "MAX_DEPTH", "MAX_EXPONENT", "MAX_LENGTH", "parse_expression"]

#: Longest accepted text, in characters.
MAX_LENGTH = 2000
#: Deepest accepted nesting (parentheses, function calls, unary signs and powers together).
MAX_DEPTH = 64
#: Largest accepted magnitude of a numeric exponent (``T1**100`` is accepted, ``T1**101`` not).
MAX_EXPONENT = 100

#: Function name -> (SymPy name, numbers of arguments accepted).
FUNCTIONS: dict[str, tuple[str, tuple[int, ...]]] = {
    "sqrt": ("sqrt", (1,)), "abs": ("Abs", (1,)), "Abs": ("Abs", (1,)),
    "exp": ("exp", (1,)), "log": ("log", (1,)), "sign": ("sign", (1,)),
    "sin": ("sin", (1,)), "cos": ("cos", (1,)), "tan": ("tan", (1,)),
    "asin": ("asin", (1,)), "acos": ("acos", (1,)), "atan": ("atan", (1,)),
    "atan2": ("atan2", (2,)),
    "sinh": ("sinh", (1,)), "cosh": ("cosh", (1,)), "tanh": ("tanh", (1,)),
    "Max": ("Max", (2, 3, 4, 5, 6, 7, 8)), "Min": ("Min", (2, 3, 4, 5, 6, 7, 8)),
    "max": ("Max", (2, 3, 4, 5, 6, 7, 8)), "min": ("Min", (2, 3, 4, 5, 6, 7, 8)),
}

#: Double-precision evaluation of each function, to check constant arguments (domain, range).
_FLOAT = {
    "sqrt": math.sqrt, "Abs": abs, "exp": math.exp, "log": math.log,
    "sign": lambda x: float((x > 0) - (x < 0)),
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos,
    "atan": math.atan, "atan2": math.atan2, "sinh": math.sinh, "cosh": math.cosh,
    "tanh": math.tanh, "Max": max, "Min": min,
}

_TOKEN = re.compile(r"""
    (?P<space>\s+)
  | (?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)
  | (?P<name>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<op>\*\*|[-+*/^(),])
""", re.VERBOSE)


@dataclass(frozen=True)
class _Token:
    kind: str       # "number", "name", "op" or "end"
    text: str
    pos: int        # 0-based character offset in the text


@dataclass(frozen=True)
class _Node:
    expr: object          # the SymPy expression
    value: float | None   # its double-precision value when it is a constant, else None


class _Parser:
    def __init__(self, text: str, symbols: Mapping, name: str):
        import sympy

        self.sp, self.text, self.symbols, self.name = sympy, text, dict(symbols), name
        self.tokens = _tokenize(text, self._fail)
        self.i = 0
        self.depth = 0

    # ---- errors and token access ------------------------------------------------------------
    def _fail(self, problem: str, token: str, pos: int, hint: str = ""):
        shown = self.text if len(self.text) <= 80 else self.text[:77] + "..."
        raise FrictionRulesError(
            f"{self.name} = {shown!r}: {problem}{f' {token!r}' if token else ''} at position {pos}"
            + (f"; {hint}" if hint else ""))

    def _allowed(self) -> str:
        names = ", ".join(sorted(self.symbols)) or "none"
        return (f"allowed: numbers, the symbols {names}, pi, E, + - * / ** ^ ( ) and the "
                f"functions {', '.join(sorted(set(FUNCTIONS)))}")

    @property
    def tok(self) -> _Token:
        return self.tokens[self.i]

    def _take(self) -> _Token:
        tok = self.tokens[self.i]
        self.i += 1
        return tok

    def _expect(self, text: str) -> _Token:
        if self.tok.text != text:
            self._unexpected(f"expected {text!r}")
        return self._take()

    def _unexpected(self, hint: str = ""):
        tok = self.tok
        if tok.kind == "end":
            self._fail("the expression ends too early", "", tok.pos, hint)
        self._fail("unexpected token", tok.text, tok.pos, hint)

    def _enter(self, tok: _Token):
        self.depth += 1
        if self.depth > MAX_DEPTH:
            self._fail(f"nesting deeper than {MAX_DEPTH} levels at", tok.text, tok.pos)

    # ---- grammar ----------------------------------------------------------------------------
    def parse(self):
        if self.tok.kind == "end":
            raise FrictionRulesError(f"{self.name} = {self.text!r} is empty; constraint: an "
                                     "expression such as 'sqrt(T1**2 + T2**2) - 0.3*N'")
        node = self._expr()
        if self.tok.kind != "end":
            self._unexpected("expected an operator (+ - * / ** ^) or the end of the expression")
        return node.expr

    def _expr(self) -> _Node:
        node = self._term()
        while self.tok.text in ("+", "-"):
            op = self._take()
            node = self._binary(op, node, self._term())
        return node

    def _term(self) -> _Node:
        node = self._unary()
        while self.tok.text in ("*", "/"):
            op = self._take()
            node = self._binary(op, node, self._unary())
        return node

    def _unary(self) -> _Node:
        if self.tok.text in ("+", "-"):
            op = self._take()
            self._enter(op)
            node = self._unary()
            self.depth -= 1
            if op.text == "+":
                return node
            return _Node(-node.expr, None if node.value is None else -node.value)
        return self._power()

    def _power(self) -> _Node:
        base = self._atom()
        if self.tok.text not in ("**", "^"):
            return base
        op = self._take()
        self._enter(op)
        exponent = self._unary()
        self.depth -= 1
        if exponent.value is not None and abs(exponent.value) > MAX_EXPONENT:
            self._fail(f"exponent {exponent.value:.6g} (constraint: |exponent| <= {MAX_EXPONENT}) "
                       "of the power", op.text, op.pos)
        value = self._constant(op, lambda a, b: a ** b, base, exponent)
        return self._checked(op, base.expr ** exponent.expr, value)

    def _atom(self) -> _Node:
        tok = self.tok
        if tok.kind == "number":
            self._take()
            return self._number(tok)
        if tok.kind == "name":
            self._take()
            if self.tok.text == "(":
                return self._call(tok)
            return self._name(tok)
        if tok.text == "(":
            self._take()
            self._enter(tok)
            node = self._expr()
            self._expect(")")
            self.depth -= 1
            return node
        self._unexpected("expected a number, a symbol, a function or '('")

    def _number(self, tok: _Token) -> _Node:
        sp = self.sp
        try:
            value = float(tok.text)
        except OverflowError:  # pragma: no cover - float() of a decimal string returns inf
            value = math.inf
        if not math.isfinite(value):
            self._fail("number out of the double-precision range", tok.text, tok.pos)
        if re.fullmatch(r"\d+", tok.text):
            return _Node(sp.Integer(int(tok.text)), value)
        return _Node(sp.Float(tok.text), value)

    def _name(self, tok: _Token) -> _Node:
        sp = self.sp
        if tok.text in self.symbols:
            return _Node(self.symbols[tok.text], None)
        if tok.text == "pi":
            return _Node(sp.pi, math.pi)
        if tok.text == "E":
            return _Node(sp.E, math.e)
        if tok.text in FUNCTIONS:
            self._fail("function without arguments", tok.text, tok.pos, "write it as name(...)")
        self._fail("unknown name", tok.text, tok.pos, self._allowed())

    def _call(self, tok: _Token) -> _Node:
        if tok.text not in FUNCTIONS:
            what = "a symbol is not a function:" if tok.text in self.symbols else "unknown function"
            self._fail(what, tok.text, tok.pos, self._allowed())
        sympy_name, arities = FUNCTIONS[tok.text]
        self._enter(tok)
        self._expect("(")
        args = [self._expr()]
        while self.tok.text == ",":
            self._take()
            args.append(self._expr())
        self._expect(")")
        self.depth -= 1
        if len(args) not in arities:
            want = " or ".join(map(str, arities)) if len(arities) < 3 else f"{arities[0]} to {arities[-1]}"
            self._fail(f"{len(args)} argument(s) (constraint: {want}) given to the function",
                       tok.text, tok.pos)
        value = self._constant(tok, _FLOAT[sympy_name], *args)
        return self._checked(tok, getattr(self.sp, sympy_name)(*(a.expr for a in args)), value)

    def _binary(self, op: _Token, left: _Node, right: _Node) -> _Node:
        fun = _BINARY[op.text]
        value = self._constant(op, fun, left, right)
        return self._checked(op, fun(left.expr, right.expr), value)

    def _constant(self, tok: _Token, fun, *args: _Node) -> float | None:
        """The double-precision value of a constant sub-expression (None if not constant),
        checked finite and real before SymPy builds it (``9**9**9`` never reaches SymPy)."""
        if any(a.value is None for a in args):
            return None
        value = _float_op(fun, *(a.value for a in args))
        if value is None:
            self._fail("no finite real value (a constant out of range or domain) for", tok.text,
                       tok.pos)
        return value

    def _checked(self, tok: _Token, expr, value) -> _Node:
        """Refuse SymPy's infinities, NaN and imaginary unit wherever they appear in a new
        node's top level (``T1/0`` is ``zoo*T1``, ``1/(T1 - T1)`` is ``zoo``)."""
        sp = self.sp
        bad = (sp.zoo, sp.oo, -sp.oo, sp.nan, sp.I)
        parts = (expr, *getattr(expr, "args", ()))
        if any(part in bad for part in parts):
            self._fail("an infinite, undefined or complex result of", tok.text, tok.pos)
        if any(part.is_Pow and part.exp.is_Number and abs(part.exp) > MAX_EXPONENT for part in parts):
            self._fail(f"a combined exponent beyond |exponent| <= {MAX_EXPONENT} after", tok.text,
                       tok.pos)
        return _Node(expr, value)


_BINARY = {"+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
           "/": lambda a, b: a / b}


def _float_op(fun, *args) -> float | None:
    """``fun(*args)`` in double precision; None where it is undefined, complex or overflows."""
    try:
        out = fun(*args)
    except (ValueError, OverflowError, ZeroDivisionError, TypeError):
        return None
    if isinstance(out, complex) or not math.isfinite(out):
        return None
    return float(out)


def _tokenize(text: str, fail) -> list[_Token]:
    tokens = []
    pos = 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None:
            fail("character not allowed", text[pos], pos,
                 "allowed: digits, letters, _, + - * / ^ ( ) , . and spaces")
        if m.lastgroup != "space":
            tokens.append(_Token(m.lastgroup, m.group(), pos))
        pos = m.end()
    tokens.append(_Token("end", "", len(text)))
    return tokens


def parse_expression(text: str, symbols: Mapping[str, object], *, name: str):
    """Parse a law expression written as text into a SymPy expression, without ``eval``.

    Parameters
    ----------
    text : str
        The expression, e.g. ``"sqrt(T1**2 + T2**2) - mu*N"`` (see the module docstring for
        the grammar: numbers, the given symbols, ``pi``, ``E``, ``+ - * /``, ``**`` or ``^``,
        parentheses and the functions of :data:`FUNCTIONS`).
    symbols : mapping of str to sympy.Symbol
        The names the text may use and the SymPy symbols they stand for (e.g. ``{"T1": T1,
        "T2": T2, "N": N, "mu": Symbol("mu")}``).
    name : str
        What the text is (``"limit"``, ``"--limit"``, ``"potential"``), for the error message.

    Returns
    -------
    sympy.Expr

    Raises
    ------
    FrictionRulesError
        For anything outside the grammar (an unknown name or function, an attribute, a
        subscript, a string, a lambda, ...), naming ``name``, the offending token and its
        0-based position; for a text longer than :data:`MAX_LENGTH`, nested deeper than
        :data:`MAX_DEPTH`, a numeric exponent beyond :data:`MAX_EXPONENT`, or a constant that
        is not a finite real number.

    Examples
    --------
    >>> import sympy
    >>> T1, T2, N = sympy.symbols("T1 T2 N")
    >>> parse_expression("sqrt(T1^2 + T2^2) - 0.3*N", {"T1": T1, "T2": T2, "N": N}, name="limit")
    -0.3*N + sqrt(T1**2 + T2**2)
    """
    if not isinstance(text, str):
        raise FrictionRulesError(f"{name} = {text!r} is not a string")
    if len(text) > MAX_LENGTH:
        raise FrictionRulesError(f"{name} has {len(text)} characters; constraint: at most "
                                 f"{MAX_LENGTH}")
    for key in symbols:
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", str(key)) or key in FUNCTIONS:
            raise FrictionRulesError(f"symbol name {key!r} violates: an identifier that is not "
                                     "a function name")
    return _Parser(text, symbols, name).parse()
