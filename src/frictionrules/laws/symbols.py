"""The SymPy symbols ``T1, T2, N`` in which user laws are written (imports SymPy)."""

import sympy

T1, T2, N = sympy.symbols("T1 T2 N", real=True)

__all__ = ["T1", "T2", "N"]
