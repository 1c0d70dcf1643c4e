"""Whitelist parser of law strings: never evaluates user text as code.

The text is parsed by :func:`ast.parse` (which builds a syntax tree and runs nothing) and every
node is checked against a whitelist: numbers, the allowed names, ``+ - * / **``, unary minus
and calls of a fixed list of functions. The SymPy expression is built from the tree directly.
"""

from __future__ import annotations

import ast
from collections.abc import Mapping

from ..errors import FrictionRulesError

__all__ = ["parse_expression", "FUNCTIONS"]

#: Longest accepted text, deepest nesting and largest exponent (a string cannot hang the process).
MAX_LENGTH = 2000
MAX_DEPTH = 60
MAX_EXPONENT = 64


def _functions():
    import sympy
    return {"sqrt": sympy.sqrt, "abs": sympy.Abs, "Abs": sympy.Abs, "exp": sympy.exp,
            "log": sympy.log, "sin": sympy.sin, "cos": sympy.cos, "tan": sympy.tan,
            "atan": sympy.atan, "atan2": sympy.atan2, "asin": sympy.asin, "acos": sympy.acos,
            "sinh": sympy.sinh, "cosh": sympy.cosh, "tanh": sympy.tanh, "Max": sympy.Max,
            "Min": sympy.Min, "max": sympy.Max, "min": sympy.Min, "sign": sympy.sign}


#: Function names a law string may call.
FUNCTIONS = ("sqrt", "abs", "Abs", "exp", "log", "sin", "cos", "tan", "atan", "atan2", "asin",
             "acos", "sinh", "cosh", "tanh", "Max", "Min", "max", "min", "sign")
_CONSTANTS = ("pi",)


def parse_expression(text: str, symbols: Mapping, *, name: str):
    """The SymPy expression of ``text`` over ``symbols`` (name -> sympy.Symbol).

    Raises :class:`FrictionRulesError` naming ``name``, the offending token and its column.
    ``^`` is read as a power, as in the paper's notation.
    """
    import sympy

    if not isinstance(text, str):
        raise FrictionRulesError(f"{name} = {text!r} violates: must be a string")
    if len(text) > MAX_LENGTH:
        raise FrictionRulesError(f"{name} is {len(text)} characters long; constraint: at most "
                                 f"{MAX_LENGTH}")
    source = text.replace("^", "**")
    try:
        tree = ast.parse(source.strip(), mode="eval")
    except SyntaxError as exc:
        raise FrictionRulesError(f"{name} = {text!r} is not an expression: {exc.msg} at column "
                                 f"{exc.offset or 1}") from None
    except (RecursionError, MemoryError, ValueError):
        raise FrictionRulesError(f"{name} = {text!r} is not an expression (too deeply nested or "
                                 "contains a null character)") from None
    funcs = _functions()

    def bad(node, what):
        token = ast.get_source_segment(source.strip(), node) or type(node).__name__
        raise FrictionRulesError(f"{name} = {text!r}: {what} {token!r} at column "
                                 f"{getattr(node, 'col_offset', 0) + 1} is not allowed (numbers, "
                                 f"{', '.join(symbols)}, + - * / ** and the functions "
                                 f"{', '.join(FUNCTIONS)})")

    def build(node, depth):
        if depth > MAX_DEPTH:
            raise FrictionRulesError(f"{name} = {text!r} is nested deeper than {MAX_DEPTH} levels")
        if isinstance(node, ast.Expression):
            return build(node.body, depth + 1)
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
                bad(node, "the constant")
            return sympy.Integer(node.value) if isinstance(node.value, int) else sympy.Float(node.value)
        if isinstance(node, ast.Name):
            if node.id in symbols:
                return symbols[node.id]
            if node.id == "pi":
                return sympy.pi
            bad(node, "the name")
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            arg = build(node.operand, depth + 1)
            return -arg if isinstance(node.op, ast.USub) else arg
        if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub, ast.Mult,
                                                                ast.Div, ast.Pow)):
            a, b = build(node.left, depth + 1), build(node.right, depth + 1)
            if isinstance(node.op, ast.Add):
                return a + b
            if isinstance(node.op, ast.Sub):
                return a - b
            if isinstance(node.op, ast.Mult):
                return a * b
            if isinstance(node.op, ast.Div):
                return a / b
            if b.is_number and abs(complex(b)) > MAX_EXPONENT:
                bad(node.right, "the exponent (|exponent| <= 64)")
            return a ** b
        if isinstance(node, ast.Call):
            if not isinstance(node.func, ast.Name) or node.func.id not in funcs or node.keywords:
                bad(node.func, "the function")
            args = [build(a, depth + 1) for a in node.args]
            try:
                return funcs[node.func.id](*args)
            except (TypeError, ValueError) as exc:
                raise FrictionRulesError(f"{name} = {text!r}: {node.func.id}() {exc}") from None
        bad(node, "the construct")

    return build(tree, 0)
