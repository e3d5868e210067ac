"""Record twelve fixed episodes, or check a new recording against an old one: a refactoring guard.

    python scripts/golden_episodes.py record DIR     # write DIR/<name>/{episode.json, steps.jsonl, ...}
    python scripts/golden_episodes.py check OLD NEW  # exit 1 and list the files that differ

The episodes cover every stepping path: the default planner (``grounded``) and the oracle on real
scenes with random starts, and the LLM planners (``more``, ``moma-llm``, ``moma-llm-sr``, ``bumble``)
against the scripted OpenAI-compatible servers of the test suite. ``episode.json`` is written with
its timings and LLM waiting times removed (in steps.jsonl too), so two recordings of unchanged behaviour are
byte-identical. Run from the repository root (the LLM episodes import ``tests``).
"""

from __future__ import annotations

import argparse
import filecmp
import json
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from more_agent.eval.episode import run_episode  # noqa: E402
from more_agent.records import EpisodeSpec  # noqa: E402

KITCHEN = ROOT / "tests" / "fixtures" / "tasks_kitchen_scene.json"
COMPARED = ("episode.json", "steps.jsonl", "timeline.jsonl")
"""Files compared between recordings (pictures and viewer pages are derived from these)."""

PLAIN: dict[str, EpisodeSpec] = {
    "grounded-kitchen": EpisodeSpec(task="putting_shopping_away", scene=str(KITCHEN), seed=0, planner="grounded"),
    "grounded-shopping-1": EpisodeSpec(task="putting_shopping_away", seed=1, planner="grounded"),
    "grounded-toys-0": EpisodeSpec(task="picking_up_toys", seed=0, planner="grounded"),
    "grounded-dishes-2": EpisodeSpec(task="putting_dishes_away_after_cleaning", seed=2, planner="grounded"),
    "oracle-shopping-0": EpisodeSpec(task="putting_shopping_away", seed=0, planner="oracle"),
    "oracle-toys-1": EpisodeSpec(task="picking_up_toys", seed=1, planner="oracle"),
    "oracle-car-0": EpisodeSpec(task="loading_the_car", seed=0, planner="oracle"),
    "oracle-books-2": EpisodeSpec(task="re_shelving_library_books", seed=2, planner="oracle"),
}


TIMING_KEYS = frozenset({"timings", "seconds", "latency_s"})
"""Keys whose values are wall-clock times: dropped before comparing."""


def _normalized(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _normalized(v) for k, v in value.items() if k not in TIMING_KEYS}
    if isinstance(value, list):
        return [_normalized(v) for v in value]
    return value


def _write_normalized(out: Path) -> None:
    """Rewrite the compared files without their timings (a sorted-key JSON document per line)."""
    path = out / "episode.json"
    path.write_text(json.dumps(_normalized(json.loads(path.read_text())), indent=1, sort_keys=True) + "\n")
    for name in COMPARED[1:]:
        path = out / name
        if path.exists():
            lines = [json.dumps(_normalized(json.loads(line)), sort_keys=True) for line in path.read_text().splitlines()]
            path.write_text("".join(line + "\n" for line in lines))


def _llm_episodes() -> dict[str, Callable[[Path], None]]:
    """The scripted-LLM episodes: name -> function that runs it into a folder."""
    from more_agent.llm import LLMConfig, make_client
    from more_agent.planners.bumble import BUMBLE_CONFIGS, BumblePlanner
    from more_agent.planners.llm_planner import PLANNER_CONFIGS, LLMClients, LLMPlanner
    from tests.planners.brain import BrainServer, RearrangeBrain
    from tests.planners.test_llm_episode import GOAL, TASK
    from tests.planners.vlm_brain import RearrangeVLM

    def client(server: BrainServer, cache: Path):
        config = LLMConfig(base_url=server.base_url, api_key="sk-test", timeout_s=5.0, max_retries=0, cache_path=cache)
        return make_client("openai:fake-model", config)

    def language(planner: str) -> Callable[[Path], None]:
        def run(out: Path) -> None:
            spec = EpisodeSpec(task=TASK, scene=str(KITCHEN), seed=0, planner=planner, llm="openai:fake-model")
            with BrainServer(RearrangeBrain(GOAL)) as server, tempfile.TemporaryDirectory() as tmp:
                chat = client(server, Path(tmp) / "cache.sqlite")
                run_episode(spec, planner=LLMPlanner(PLANNER_CONFIGS[planner], LLMClients(chat, chat, "openai:fake-model")),
                            out_dir=out)
        return run

    def bumble(out: Path) -> None:
        spec = EpisodeSpec(task=TASK, scene=str(KITCHEN), seed=0, planner="bumble", llm="openai:fake-model")
        with BrainServer(RearrangeVLM(GOAL)) as server, tempfile.TemporaryDirectory() as tmp:
            planner = BumblePlanner(BUMBLE_CONFIGS["bumble"], client(server, Path(tmp) / "cache.sqlite"), "openai:fake-model")
            run_episode(spec, planner=planner, out_dir=out)

    return {"more-kitchen": language("more"), "moma-llm-kitchen": language("moma-llm"),
            "moma-llm-sr-kitchen": language("moma-llm-sr"), "bumble-kitchen": bumble}


def record(root: Path) -> None:
    """Run the twelve episodes into ``root/<name>/``."""
    runs: dict[str, Callable[[Path], None]] = {
        name: (lambda out, spec=spec: run_episode(spec, out_dir=out)) for name, spec in PLAIN.items()
    }
    runs.update(_llm_episodes())
    for name, run in runs.items():
        out = root / name
        out.mkdir(parents=True, exist_ok=True)
        run(out)
        _write_normalized(out)
        print(f"{name}: {json.loads((out / 'episode.json').read_text()).get('success')}", flush=True)


def check(old: Path, new: Path) -> int:
    """Compare two recordings file by file; print what differs; 0 when identical."""
    differing = []
    for folder in sorted(p for p in old.iterdir() if p.is_dir()):
        for name in COMPARED:
            a, b = folder / name, new / folder.name / name
            if a.exists() != b.exists() or (a.exists() and not filecmp.cmp(a, b, shallow=False)):
                differing.append(f"{folder.name}/{name}")
    print("\n".join(differing) or f"identical: {len(list(old.iterdir()))} episodes")
    return 1 if differing else 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("record").add_argument("dir", type=Path)
    compare = sub.add_parser("check")
    compare.add_argument("old", type=Path)
    compare.add_argument("new", type=Path)
    args = parser.parse_args()
    if args.command == "record":
        record(args.dir)
        return 0
    return check(args.old, args.new)


if __name__ == "__main__":
    sys.exit(main())
