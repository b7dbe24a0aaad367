"""How long ``stealth --help`` takes: this tree against a reference tree, back to back.

Every command pays for building the parser before it does anything, so ``--help`` measures
the start-up of the command line. Each run is a fresh interpreter (``python -m headless.cli
--help``, the tree as its working directory and ``PYTHONPATH``, so it imports that tree and
not the editable install); the two trees alternate run by run, so a machine whose load
changes slows both alike. Prints each tree's median and fastest run and the ratio of the
medians, and whether both printed the same help.

Run: ``python benchmarks/cli_help.py --reference /work/base [--runs 21]`` (a checkout of
the code before the change); without ``--reference`` only this tree is timed.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import _paths  # noqa: F401  (project importable, this folder unshadowed)


def help_run(tree: Path) -> tuple[float, str]:
    """Wall seconds of one ``stealth --help`` in a fresh interpreter on ``tree``, and its output."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "headless.cli", "--help"], cwd=tree, env=env,
                          capture_output=True, text=True, timeout=120)
    elapsed = time.perf_counter() - started
    if done.returncode:
        raise SystemExit(f"cli_help: {tree}: stealth --help failed: {done.stderr.strip()[-300:]}")
    return elapsed, done.stdout


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", type=Path, default=None, metavar="DIR",
                        help="a checkout to compare with (default: time this tree only)")
    parser.add_argument("--runs", type=int, default=21, help="runs per tree (median taken)")
    args = parser.parse_args()
    trees = {"this tree": _paths.ROOT}
    if args.reference is not None:
        if not (args.reference / "headless" / "cli.py").is_file():
            raise SystemExit(f"cli_help: --reference {args.reference}: not a checkout "
                             "(no headless/cli.py)")
        trees["reference"] = args.reference.resolve()
    times: dict[str, list[float]] = {name: [] for name in trees}
    outputs: dict[str, str] = {}
    for name, tree in trees.items():  # warm-up: byte-compile, fill the file cache
        outputs[name] = help_run(tree)[1]
    for _ in range(args.runs):
        for name, tree in trees.items():
            times[name].append(help_run(tree)[0])
    print(f"stealth --help, {args.runs} fresh interpreters per tree, alternating "
          f"(python {sys.version.split()[0]}, {os.cpu_count()} CPUs)")
    for name, tree in trees.items():
        print(f"  {name:<10} {tree}: median {statistics.median(times[name]) * 1e3:7.1f} ms, "
              f"fastest {min(times[name]) * 1e3:7.1f} ms")
    if "reference" in trees:
        ratio = statistics.median(times["reference"]) / statistics.median(times["this tree"])
        print(f"  ratio of the medians: this tree is {ratio:.2f}x as fast as the reference")
        same = outputs["reference"] == outputs["this tree"]
        print(f"  same help text: {'yes' if same else 'no'}")


if __name__ == "__main__":
    main()
