"""Test-suite settings.

Under CI (``CI`` set in the environment) hypothesis runs derandomized: the same examples on
every run, so a red CI is always reproducible. Local runs keep drawing fresh examples and
keep exploring; a failure prints the blob to reproduce it.
"""

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("dev", print_blob=True)
settings.load_profile("ci" if os.environ.get("CI") else "dev")

# The game keeps the player's best results in the user's data directory: never the real one
# from the tests (each test process gets a fresh one).
if "STEALTHFIELD_DATA" not in os.environ:
    import tempfile

    os.environ["STEALTHFIELD_DATA"] = tempfile.mkdtemp(prefix="stealthfield-data-")


import pytest  # noqa: E402


@pytest.fixture(autouse=True)
def _zone_kinds_restored():
    """A test that loads a stimulus plugin registers its zone kinds process-wide; the next
    test in the same worker must still see only the built-in kinds (test order varies with
    pytest-xdist's scheduling)."""
    from navmesh import level_fields

    kinds = list(level_fields._zone_kinds)
    yield
    level_fields._zone_kinds[:] = kinds
