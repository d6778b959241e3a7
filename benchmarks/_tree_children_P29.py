"""Paired runs of a benchmark's child in two (or more) source trees: one process per tree and run.

The trees are taken alternately (A, B, A, B, ...), so that a change in the machine's load falls on both alike;
each child runs with ``PYTHONPATH=<tree>/src`` (the venv's editable install otherwise points at the working tree)
and prints one JSON object per line, read back here. Shared by ``benchmarks/cloud_speed_C28.py`` and
``benchmarks/pointcloud_speed_P24.py``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path


def alternate_rows(script: str, trees, runs: int, child_arguments) -> Iterator[tuple[str, int, dict]]:
    """``(tree, run, row)`` for each JSON line printed by ``python <script> --child <child_arguments>`` run once
    per tree and run (``run`` from 1), the trees alternately."""
    for run in range(1, runs + 1):
        for tree in trees:
            env = {**os.environ, "PYTHONPATH": str(Path(tree).resolve() / "src")}
            command = [sys.executable, script, "--child", *map(str, child_arguments)]
            output = subprocess.run(command, env=env, check=True, capture_output=True, text=True).stdout
            for line in output.splitlines():
                if line.startswith("{"):
                    yield tree, run, json.loads(line)
