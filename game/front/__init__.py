"""The interactive pygame-ce front end: the only package that imports pygame."""

import os

# Before any module of the package imports pygame: no "Hello from the pygame community" banner.
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
