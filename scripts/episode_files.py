"""Count the package's files one episode passes through, from ``run_episode`` to ``episode.json``.

    python scripts/episode_files.py TASK PLANNER   # e.g. bringing_in_wood grounded (seed 0)

The episode runs twice; the second run is profiled (the first warms the imports), instantiation
included. Prints the count, then the files, one a line. docs/architecture.md gives today's figure.
"""

from __future__ import annotations

import argparse
import collections
import sys
import tempfile
from pathlib import Path
from types import FrameType
from typing import Any

import more_agent
from more_agent.eval.episode import run_episode
from more_agent.records import EpisodeSpec

ROOT = str(Path(more_agent.__file__).parent)


def files_of_episode(spec: EpisodeSpec) -> collections.Counter[str]:
    """Package file (relative to the package) -> how many calls the profiled episode made into it."""
    files: collections.Counter[str] = collections.Counter()

    def profile(frame: FrameType, event: str, arg: Any) -> None:
        path = frame.f_code.co_filename
        if event == "call" and path.startswith(ROOT):
            files[path[len(ROOT) + 1 :]] += 1

    with tempfile.TemporaryDirectory() as folder:
        run_episode(spec, out_dir=Path(folder))  # warm the imports
        sys.setprofile(profile)
        try:
            run_episode(spec, out_dir=Path(folder))
        finally:
            sys.setprofile(None)
    return files


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("task")
    parser.add_argument("planner")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    files = files_of_episode(EpisodeSpec(task=args.task, planner=args.planner, seed=args.seed))
    print(len(files), "files")
    for name in sorted(files):
        print(" ", name)


if __name__ == "__main__":
    main()
