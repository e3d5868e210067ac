"""The scene-graph picture is a PNG."""

from more_agent.viz.graph_plot import scene_graph_png
from tests.scene_graph.scenes import explore, new_builder, two_rooms


def test_scene_graph_png_is_a_picture() -> None:
    boxes, infos = two_rooms()
    builder = new_builder()
    explore(builder, boxes, infos, [(2.0, 2.0), (5.5, 2.0)], n_yaw=6)
    data = scene_graph_png(builder.build((2.0, 2.0)).with_room_labels({"region_0": "kitchen"}))
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
