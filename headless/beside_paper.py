"""``python -m headless.beside_paper``: the entry point of :mod:`headless.analysis.beside_paper` (docs/results.md)."""

from headless.analysis.beside_paper import *  # noqa: F403 — the old import path keeps every name
from headless.analysis.beside_paper import main

if __name__ == "__main__":
    raise SystemExit(main())
