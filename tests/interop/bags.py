"""Test helpers: a short episode recorded as a bag, and bags rewritten message by message (dropped
topics, other encodings, edited label tables) to make the broken bags a robot may hand us."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rosbags.rosbag2 import Reader, StoragePlugin, Writer

from more_agent.eval.episode import run_episode
from more_agent.interop.bag_contract import typestore
from more_agent.interop.bag_writer import BagRecorder
from more_agent.planners.base import make_planner
from more_agent.records import EpisodeSpec
from more_agent.scene_graph import SceneGraph

# Seed 0 carries cup_of_yogurt A in a sack: the live robot, which builds a graph every step, and the ingest,
# which builds once, boxed it 0.07 m apart until a build stopped keeping boxes of its own (2026-12-03).
SPEC = EpisodeSpec(task="putting_shopping_away", scene="Rs_int", seed=0, planner="grounded")
"""A short successful episode (13 steps): opens, grasps and places, so the bag holds opened
containers and put-down items."""

Edit = Callable[[str, Any], tuple[str, Any] | None]
"""(topic, message) -> (topic, message) to write, or None to drop it."""


@dataclass(frozen=True)
class Recorded:
    bag: Path
    live: SceneGraph
    """The live robot's final scene graph (built from everything it sensed)."""
    frames: int


def record_episode(bag: Path) -> Recorded:
    planner = make_planner(SPEC.planner, None)
    with BagRecorder(bag, storage="mcap") as recorder:
        record = run_episode(SPEC, planner=planner, bag=recorder)
    assert record.success and record.error is None
    return Recorded(bag=bag, live=planner.body.build(), frames=recorder.frames)


def rewrite_bag(src: Path, dst: Path, edit: Edit = lambda topic, msg: (topic, msg), *,
                storage: StoragePlugin = StoragePlugin.MCAP, until_s: float | None = None) -> Path:
    """Copy ``src`` (up to ``until_s`` seconds of it) to a new bag ``dst``, each message through ``edit``."""
    store = typestore()
    conns: dict[str, Any] = {}
    stop = None if until_s is None else round(until_s * 1e9)
    with Reader(src) as reader, Writer(dst, version=Writer.VERSION_LATEST, storage_plugin=storage) as writer:
        for conn, t_ns, raw in reader.messages(stop=stop):
            edited = edit(conn.topic, store.deserialize_cdr(raw, conn.msgtype))
            if edited is None:
                continue
            topic, msg = edited
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msg.__msgtype__, typestore=store)
            writer.write(conns[topic], t_ns, store.serialize_cdr(msg, msg.__msgtype__))
    return dst
