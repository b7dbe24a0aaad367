"""``python -m headless.held_out``: the entry point of :mod:`headless.analysis.held_out` (docs/results.md)."""

from headless.analysis.held_out import *  # noqa: F403 — the old import path keeps every name
from headless.analysis.held_out import main

if __name__ == "__main__":
    raise SystemExit(main())
