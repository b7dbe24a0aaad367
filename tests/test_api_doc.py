"""docs/api.md: every Python block runs as written, in order, in one namespace."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import pytest

import navmesh.level_fields as level_module

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "api.md"


def blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.DOTALL)


def test_every_python_block_of_the_api_doc_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    monkeypatch.setattr(level_module, "_zone_kinds", list(level_module.ZONE_KINDS))
    found = blocks()
    assert len(found) >= 6  # one trial, a design, a store, a world, a plugin, environments
    namespace: dict = {"__name__": "api_doc"}
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        for code in found:
            exec(compile(code, str(DOC), "exec"), namespace)  # noqa: S102 (our own docs)
    text = printed.getvalue()
    assert "4 trials" in text
    assert "(4, 0)" in text  # store.count(): 4 finished, 0 failed
    assert "4 alarm zones; alert" in text
    rows = namespace["rows"]
    assert sorted(rows["guards"].unique()) == ["pf", "random"]
    assert {"key", "seed", "captured", "first_detect_time", "wall_time"} <= set(rows.columns)


def test_rows_without_pandas_are_a_list_of_dicts(monkeypatch: pytest.MonkeyPatch) -> None:
    import builtins

    from headless.api import as_rows

    real_import = builtins.__import__

    def no_pandas(name, *args, **kwargs):
        if name == "pandas":
            raise ImportError("no pandas here")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_pandas)
    assert as_rows([{"a": 1}]) == [{"a": 1}]


def test_load_store_of_a_directory_without_one_is_a_user_error(tmp_path: Path) -> None:
    from headless.api import load_store
    from headless.errors import UserError

    with pytest.raises(UserError, match="no results store here"):
        load_store(tmp_path)
