"""``python -m headless.robustness``: the entry point of :mod:`headless.analysis.robustness` (docs/results.md)."""

from headless.analysis.robustness import *  # noqa: F403 — the old import path keeps every name
from headless.analysis.robustness import main

if __name__ == "__main__":
    raise SystemExit(main())
