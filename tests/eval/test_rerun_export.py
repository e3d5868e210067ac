"""``more-agent view DIR --rerun out.rrd``: the recording, opened with the Rerun SDK, holds per step the
camera frames, the voxel map, the robot path, the scene graph and the chosen action (marker ``rerun``:
the 'rerun' extra, installed by .ci/run in its own step)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from more_agent.cli import app

if TYPE_CHECKING:
    import pyarrow as pa

pytestmark = pytest.mark.rerun


def _entities(path) -> dict[str, list[pa.RecordBatch]]:
    from rerun.chunk import RrdReader

    found: dict[str, list[pa.RecordBatch]] = {}
    for chunk in RrdReader(path).stream():
        found.setdefault(chunk.entity_path, []).append(chunk.to_record_batch())
    return found


def _column(batches: list[pa.RecordBatch], name: str) -> list:
    return [v for b in batches if name in b.schema.names for v in b.column(name).to_pylist()]


def test_the_recording_holds_frames_map_path_graph_and_actions(llm_episode, tmp_path):
    out = tmp_path / "episode.rrd"
    result = CliRunner().invoke(app, ["view", str(llm_episode.dir), "--rerun", str(out)])
    assert result.exit_code == 0, result.output
    entities = _entities(out)
    steps = len(llm_episode.record.actions)
    for entity in ("/camera/rgb", "/camera/depth", "/camera/semantic"):
        assert sum(b.num_rows for b in entities[entity]) == len(list((llm_episode.dir / "frames").glob("*_rgb.png")))
    for entity in ("/world/map", "/world/robot/path", "/world/graph/objects", "/world/graph/regions",
                   "/world/graph/places", "/world/graph/nav_edges", "/world/graph/edges", "/action"):
        assert sum(b.num_rows for b in entities[entity]) == steps, entity
    texts = [t[0] for t in _column(entities["/action"], "TextLog:text")]
    assert texts[0].startswith(f"step 0: {llm_episode.record.actions[0].name}(")
    labels = {label for row in _column(entities["/world/graph/objects"], "Boxes3D:labels") for label in row}
    assert "fridge A" in labels


def test_view_rerun_needs_an_episode_folder(tmp_path):
    result = CliRunner().invoke(app, ["view", str(tmp_path), "--rerun", str(tmp_path / "x.rrd")])
    assert result.exit_code == 2 and "not an episode folder" in result.output
