"""Import first in every benchmark script: makes the project importable, unshadowed.

Run as ``python benchmarks/NAME.py``, this folder is ``sys.path[0]`` and a script named
like a package (``ai.py``) would shadow it; this swaps the folder for the project root.
``tests/`` goes on the path too, so benchmarks import the test oracle (``tests/oracle.py``)
under the same name the tests do.
"""

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path[:] = [p for p in sys.path if Path(p or ".").resolve() != HERE]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))
if str(ROOT / "tests") not in sys.path:
    sys.path.append(str(ROOT / "tests"))
# last, so nothing here shadows the project, yet a worker process started by ``spawn``
# (which imports the running script again, on this path) still finds this module
sys.path.append(str(HERE))
