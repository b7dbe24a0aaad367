"""Metric expressions of ``stealth tune`` objectives and constraints, parsed with :mod:`ast`.

An expression is arithmetic (``+ - * / **``, unary minus, numbers, ``abs``/``min``/``max``)
over metric names — the registry's metric names (``captured``, ``captures``,
``backtracks``, …) and ``capture_rate`` for ``captured`` — each the design's mean of that
metric over the trials of its scenario. A name may be narrowed by dotted selectors: guard
modes, player policies, abstractions (``pf.captures - staleness.captures``,
``grid.pf.capture_rate``). A constraint is one comparison (``backtracks <= 10``). Nothing is
``eval``-ed: any other syntax is a one-line :class:`~headless.errors.UserError`.

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
import operator
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..errors import UserError

__all__ = ["Expression", "Lookup", "parse_constraint", "parse_expression"]

#: ``lookup(metric name, selectors) -> value`` (the caller aggregates the trials)
Lookup = Callable[[str, tuple[str, ...]], float]

_BINARY: dict[type[ast.operator], Callable[[float, float], float]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
    ast.Div: operator.truediv, ast.Pow: operator.pow,
}
_CALLS: dict[str, Callable[..., float]] = {"abs": abs, "min": min, "max": max}


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
        """Its value with every metric reference read through ``lookup``."""
        return float(_evaluate(self.tree, lookup))


def _evaluate(node: ast.expr, lookup: Lookup) -> Any:
    if isinstance(node, ast.Constant):
        return node.value
    if isinstance(node, ast.BinOp):
        return _BINARY[type(node.op)](_evaluate(node.left, lookup), _evaluate(node.right, lookup))
    if isinstance(node, ast.UnaryOp):
        value = _evaluate(node.operand, lookup)
        return -value if isinstance(node.op, ast.USub) else value
    if isinstance(node, ast.Call):
        assert isinstance(node.func, ast.Name)
        return _CALLS[node.func.id](*(_evaluate(a, lookup) for a in node.args))
    reference = _reference(node)
    assert reference is not None
    return lookup(*reference)


def _check(node: ast.expr, text: str, names: list[tuple[str, tuple[str, ...]]]) -> None:
    """Accept only the grammar of the module docstring; collect the metric references."""
    def bad(what: str) -> UserError:
        return UserError(f"expression {text!r}: {what} is not allowed (arithmetic over metric "
                         "names only)")
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise bad(f"the constant {node.value!r}")
    elif isinstance(node, ast.BinOp):
        if type(node.op) not in _BINARY:
            raise bad(f"the operator {type(node.op).__name__}")
        _check(node.left, text, names)
        _check(node.right, text, names)
    elif isinstance(node, ast.UnaryOp):
        if not isinstance(node.op, (ast.USub, ast.UAdd)):
            raise bad(f"the operator {type(node.op).__name__}")
        _check(node.operand, text, names)
    elif isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name) or node.func.id not in _CALLS or node.keywords:
            raise bad("this call")
        if not node.args:
            raise bad("a call without arguments")
        for arg in node.args:
            _check(arg, text, names)
    else:
        reference = _reference(node)
        if reference is None:
            raise bad(type(node).__name__)
        names.append(reference)


def parse_expression(text: str) -> Expression:
    """Parse an objective expression (one-line :class:`UserError` when it is not one)."""
    if not isinstance(text, str) or not text.strip():
        raise UserError(f"expression {text!r}: expected a metric expression")
    try:
        tree = ast.parse(text.strip(), mode="eval").body
    except SyntaxError as error:
        raise UserError(f"expression {text!r}: not an expression ({error.msg})") from None
    names: list[tuple[str, tuple[str, ...]]] = []
    _check(tree, text, names)
    if not names:
        raise UserError(f"expression {text!r}: names no metric")
    return Expression(text, tree, tuple(dict.fromkeys(names)))


def parse_constraint(text: str) -> Expression:
    """Parse ``left <= right`` (or ``<``, ``>=``, ``>``) as ``left - right`` (or its negation):
    an expression that is ``<= 0`` exactly when the constraint holds (Optuna's convention)."""
    try:
        tree = ast.parse(text.strip(), mode="eval").body if isinstance(text, str) else None
    except SyntaxError as error:
        raise UserError(f"constraint {text!r}: not a comparison ({error.msg})") from None
    if (not isinstance(tree, ast.Compare) or len(tree.ops) != 1
            or not isinstance(tree.ops[0], (ast.LtE, ast.Lt, ast.GtE, ast.Gt))):
        raise UserError(f"constraint {text!r}: expected one comparison, e.g. 'backtracks <= 10'")
    left, right = tree.left, tree.comparators[0]
    if isinstance(tree.ops[0], (ast.GtE, ast.Gt)):
        left, right = right, left
    body = ast.BinOp(left=left, op=ast.Sub(), right=right)
    names: list[tuple[str, tuple[str, ...]]] = []
    _check(body, text, names)
    if not names:
        raise UserError(f"constraint {text!r}: names no metric")
    return Expression(text, body, tuple(dict.fromkeys(names)))
