"""The scene-graph picture is written as a PNG."""

from more_agent.viz.graph_plot import plot_scene_graph
from tests.scene_graph.scenes import explore, new_builder, two_rooms


def test_plot_scene_graph_writes_png(tmp_path) -> None:
    boxes, infos = two_rooms()
    builder = new_builder()
    explore(builder, boxes, infos, [(2.0, 2.0), (5.5, 2.0)], n_yaw=6)
    out = plot_scene_graph(builder.build((2.0, 2.0)).with_room_labels({"region_0": "kitchen"}), tmp_path / "g.png")
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
