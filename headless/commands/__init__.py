"""The ``stealth`` commands that answer at once in the command line's process (levels, validate, path, sim); the parser is :mod:`headless.cli`."""
