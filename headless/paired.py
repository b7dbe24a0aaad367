"""``python -m headless.paired``: the entry point of :mod:`headless.analysis.paired` (docs/results.md)."""

from headless.analysis.paired import *  # noqa: F403 — the old import path keeps every name
from headless.analysis.paired import main

if __name__ == "__main__":
    raise SystemExit(main())
