"""Metric expressions of ``stealth tune`` objectives and constraints, parsed with :mod:`ast`.

An expression is arithmetic (``+ - * / **``, unary minus, numbers, ``abs``/``min``/``max``)
over metric names — the registry's metric names (``captured``, ``captures``,
``backtracks``, …) and ``capture_rate`` for ``captured`` — each the design's mean of that
metric over the trials of its scenario. A name may be narrowed by dotted selectors: guard
modes, player policies, abstractions (``pf.captures - staleness.captures``,
``grid.pf.capture_rate``). A constraint is one comparison (``backtracks <= 10``). Nothing is
``eval``-ed: any other syntax is a one-line :class:`~headless.errors.UserError`.

The work is bounded: the text is at most :data:`MAX_TEXT` characters and :data:`MAX_DEPTH`
levels deep, arithmetic is in floats (``**`` is :func:`math.pow`: ``9**9**9`` overflows at
once instead of building a 370-million-digit integer), and whatever arithmetic cannot do —
divide by zero, overflow, a complex result — is an :class:`ExpressionError` of one line.
Parts made of constants only are computed when the expression is parsed, so
``captures + 9**9**9`` is refused before any trial runs.

>>> objective = parse_expression("captures - 0.05*backtracks")
>>> objective.names
(('captures', ()), ('backtracks', ()))
>>> objective.evaluate(lambda name, selectors: {"captures": 3.0, "backtracks": 20.0}[name])
2.0
>>> parse_constraint("pf.backtracks <= 10").evaluate(lambda n, s: 12.0)   # > 0: violated
2.0
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..errors import UserError

__all__ = ["MAX_DEPTH", "MAX_TEXT", "Expression", "ExpressionError", "Lookup",
           "parse_constraint", "parse_expression"]

MAX_TEXT = 10_000
"""Longest expression text accepted (characters)."""
MAX_DEPTH = 100
"""Deepest nesting of operators and calls accepted."""


class ExpressionError(UserError):
    """An expression's arithmetic failed (division by zero, overflow, a complex result)."""

#: ``lookup(metric name, selectors) -> value`` (the caller aggregates the trials)
Lookup = Callable[[str, tuple[str, ...]], float]

_BINARY: dict[type[ast.operator], Callable[[float, float], float]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
    ast.Div: operator.truediv, ast.Pow: math.pow,
}
_CALLS: dict[str, Callable[..., float]] = {"abs": abs, "min": min, "max": max}
#: how many arguments each call takes: (least, most)
_ARITY: dict[str, tuple[int, int]] = {"abs": (1, 1), "min": (2, 64), "max": (2, 64)}
_SYMBOL = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**"}


def _short(text: str) -> str:
    """``text`` as an error message quotes it: at most 80 characters."""
    return text if len(text) <= 80 else text[:77] + "..."


def _reference(node: ast.expr) -> tuple[str, tuple[str, ...]] | None:
    """``a.b.metric`` as ``("metric", ("a", "b"))``; None for anything else."""
    selectors: list[str] = []
    while isinstance(node, ast.Attribute):
        selectors.insert(0, node.attr)
        node = node.value
    if not isinstance(node, ast.Name):
        return None
    parts = [node.id, *selectors]
    return parts[-1], tuple(parts[:-1])


@dataclass(frozen=True)
class Expression:
    """A parsed expression: its text, tree and the metric references it reads."""

    text: str
    tree: ast.expr
    names: tuple[tuple[str, tuple[str, ...]], ...]

    def evaluate(self, lookup: Lookup) -> float:
        """Its value with every metric reference read through ``lookup``
        (:class:`ExpressionError` when the arithmetic fails)."""
        return _evaluate(self.tree, lookup, self.text)


def _arithmetic(op: type[ast.operator], left: float, right: float, text: str) -> float:
    """``left op right`` in floats; its failure as one line."""
    try:
        value = _BINARY[op](left, right)
    except ZeroDivisionError:
        raise ExpressionError(f"expression {_short(text)!r}: division by zero") from None
    except OverflowError:
        raise ExpressionError(f"expression {_short(text)!r}: overflow ({left:g} {_SYMBOL[op]} "
                              f"{right:g} is too large for a float)") from None
    except ValueError:  # math.pow: 0 to a negative power, or a negative base and a fraction
        if left == 0:
            raise ExpressionError(f"expression {_short(text)!r}: division by zero (0 ** {right:g})"
                                  ) from None
        raise ExpressionError(f"expression {_short(text)!r}: {left:g} ** {right:g} has no real value "
                              "(a complex result)") from None
    if math.isinf(value) and math.isfinite(left) and math.isfinite(right):
        raise ExpressionError(f"expression {_short(text)!r}: overflow ({left:g} {_SYMBOL[op]} "
                              f"{right:g} is too large for a float)")
    return value


def _evaluate(node: ast.expr, lookup: Lookup | None, text: str) -> float:
    """The value of ``node`` (a checked tree); ``lookup=None`` for a constant-only part."""
    if isinstance(node, ast.Constant):
        try:
            return float(node.value)  # type: ignore[arg-type]  # checked: int or float
        except OverflowError:
            raise ExpressionError(f"expression {_short(text)!r}: the constant {str(node.value)[:20]}… "
                                  "is too large for a float") from None
    if isinstance(node, ast.BinOp):
        return _arithmetic(type(node.op), _evaluate(node.left, lookup, text),
                           _evaluate(node.right, lookup, text), text)
    if isinstance(node, ast.UnaryOp):
        value = _evaluate(node.operand, lookup, text)
        return -value if isinstance(node.op, ast.USub) else value
    if isinstance(node, ast.Call):
        assert isinstance(node.func, ast.Name)
        return float(_CALLS[node.func.id](*(_evaluate(a, lookup, text) for a in node.args)))
    reference = _reference(node)
    assert reference is not None and lookup is not None
    return float(lookup(*reference))


def _constant(node: ast.expr) -> bool:
    """Whether ``node`` reads no metric (so it can be computed now)."""
    return all(not isinstance(n, (ast.Name, ast.Attribute)) or
               (isinstance(n, ast.Name) and n.id in _CALLS) for n in ast.walk(node))


def _check(node: ast.expr, text: str, names: list[tuple[str, tuple[str, ...]]],
           depth: int = 0) -> None:
    """Accept only the grammar of the module docstring; collect the metric references."""
    def bad(what: str) -> UserError:
        return UserError(f"expression {_short(text)!r}: {what} is not allowed (arithmetic over metric "
                         "names only)")
    if depth > MAX_DEPTH:
        raise UserError(f"expression {text[:40]!r}…: nested more than {MAX_DEPTH} levels deep")
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise bad(f"the constant {node.value!r}")
    elif isinstance(node, ast.BinOp):
        if type(node.op) not in _BINARY:
            raise bad(f"the operator {type(node.op).__name__}")
        _check(node.left, text, names, depth + 1)
        _check(node.right, text, names, depth + 1)
    elif isinstance(node, ast.UnaryOp):
        if not isinstance(node.op, (ast.USub, ast.UAdd)):
            raise bad(f"the operator {type(node.op).__name__}")
        _check(node.operand, text, names, depth + 1)
    elif isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name) or node.func.id not in _CALLS or node.keywords:
            raise bad("this call")
        if not node.args:
            raise bad("a call without arguments")
        least, most = _ARITY[node.func.id]
        if not least <= len(node.args) <= most:
            raise UserError(f"expression {_short(text)!r}: {node.func.id}() takes "
                            + (f"{least} argument" if least == most
                               else f"{least} to {most} arguments")
                            + f", got {len(node.args)}")
        for arg in node.args:
            _check(arg, text, names, depth + 1)
    else:
        reference = _reference(node)
        if reference is None:
            raise bad(type(node).__name__)
        names.append(reference)
    if depth == 0:  # once, over the whole checked tree: fold what reads no metric
        _fold(node, text)


def _fold(node: ast.expr, text: str) -> None:
    """Compute every constant-only part now, so its arithmetic errors come before any trial."""
    if _constant(node):
        _evaluate(node, None, text)
        return
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.expr) and not isinstance(child, ast.Name):
            _fold(child, text)


def _parse(text: str, what: str) -> ast.expr:
    """``ast.parse`` of a bounded text: one line for what Python's parser cannot take."""
    if len(text) > MAX_TEXT:
        raise UserError(f"{what} {text[:40]!r}…: longer than {MAX_TEXT} characters")
    try:
        return ast.parse(text.strip(), mode="eval").body
    except SyntaxError as error:
        raise UserError(f"{what} {text[:200]!r}: not an expression ({error.msg})") from None
    except (RecursionError, MemoryError):
        raise UserError(f"{what} {text[:40]!r}…: nested more than {MAX_DEPTH} levels deep"
                        ) from None


def parse_expression(text: str) -> Expression:
    """Parse an objective expression (one-line :class:`UserError` when it is not one)."""
    if not isinstance(text, str) or not text.strip():
        raise UserError(f"expression {_short(text)!r}: expected a metric expression")
    tree = _parse(text, "expression")
    names: list[tuple[str, tuple[str, ...]]] = []
    _check(tree, text, names)
    if not names:
        raise UserError(f"expression {_short(text)!r}: names no metric")
    return Expression(text, tree, tuple(dict.fromkeys(names)))


def parse_constraint(text: str) -> Expression:
    """Parse ``left <= right`` (or ``<``, ``>=``, ``>``) as ``left - right`` (or its negation):
    an expression that is ``<= 0`` exactly when the constraint holds (Optuna's convention)."""
    tree = _parse(text, "constraint") if isinstance(text, str) else None
    if (not isinstance(tree, ast.Compare) or len(tree.ops) != 1
            or not isinstance(tree.ops[0], (ast.LtE, ast.Lt, ast.GtE, ast.Gt))):
        raise UserError(f"constraint {_short(text)!r}: expected one comparison, e.g. 'backtracks <= 10'")
    left, right = tree.left, tree.comparators[0]
    if isinstance(tree.ops[0], (ast.GtE, ast.Gt)):
        left, right = right, left
    body = ast.BinOp(left=left, op=ast.Sub(), right=right)
    names: list[tuple[str, tuple[str, ...]]] = []
    _check(body, text, names)
    if not names:
        raise UserError(f"constraint {_short(text)!r}: names no metric")
    return Expression(text, body, tuple(dict.fromkeys(names)))
