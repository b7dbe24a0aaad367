"""How a command answers: one JSON document on stdout (``--json``), exit code 2 after a user's mistake."""

from __future__ import annotations

import json
import sys
from typing import Any

__all__ = ["EXIT_USER_ERROR"]

EXIT_USER_ERROR = 2


def _emit_json(document: Any) -> None:
    json.dump(document, sys.stdout, indent=2)
    sys.stdout.write("\n")
