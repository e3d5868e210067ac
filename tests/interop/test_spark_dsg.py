"""Spark-DSG both ways: MORE's graph saved in Spark-DSG's formats and read back unchanged; Hydra-style
graphs (built through spark-dsg's API, and a real Hydra output) read into MORE's graph, where MORE's
filter and planner run."""

from __future__ import annotations

import json

import pytest

from more_agent.interop.spark_dsg import SparkDsgError, from_spark_dsg, load_spark_dsg, save_spark_dsg
from more_agent.planners.language import scene_view
from more_agent.planners.llm_planner import PLANNER_CONFIGS
from more_agent.service.decision import decide
from tests.fakes.decision_brain import DecisionBrain, clients
from tests.fakes.openai_server import FakeOpenAIServer
from tests.interop.hydra import APARTMENT_LABELS, apartment, kitchen_and_hall


@pytest.mark.parametrize("suffix", [".json", ".sparkdsg", ".bson"])
def test_our_graph_survives_spark_dsg_files_unchanged(recorded, tmp_path, suffix):
    path = tmp_path / f"graph{suffix}"
    save_spark_dsg(recorded.live, path)
    assert json.loads(load_spark_dsg(path).model_dump_json()) == json.loads(recorded.live.model_dump_json())


def test_saving_under_another_suffix_is_refused(recorded, tmp_path):
    with pytest.raises(SparkDsgError, match=r"end in \.json, \.sparkdsg, \.bson"):
        save_spark_dsg(recorded.live, tmp_path / "graph.bin")


def test_a_hydra_graph_becomes_regions_objects_relations_and_a_navigation_graph():
    graph = from_spark_dsg(kitchen_and_hall())
    assert sorted((o.id, o.category, o.region_id) for o in graph.objects.values()) == [
        ("chair A", "chair", "region_0"), ("cup A", "cup", "region_0"), ("fridge A", "fridge", "region_1"),
        ("table A", "table", "region_0")]
    assert graph.nav.node_region == ["region_0"] * 3 + ["region_1"] * 3  # p5 joins the room it hangs off
    assert graph.nav.edges.tolist() == [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5]]
    assert [(r.subject, r.predicate, r.object) for r in graph.relations] == [("cup A", "ontop", "table A")]
    assert graph.regions["region_1"].frontiers == [(7.0, 1.0)]
    assert graph.robot.position == (0.0, 0.0) and graph.robot.region_id == "region_0"


def test_labels_come_from_the_label_map_over_the_graph_label_space_and_missing_ones_fail():
    relabelled = from_spark_dsg(kitchen_and_hall(), {1: "mug"})
    assert "mug A" in relabelled.objects and "cup A" not in relabelled.objects
    assert "cup A" in from_spark_dsg(kitchen_and_hall(labelspace=False), {0: "table", 1: "cup", 2: "fridge", 3: "chair"}).objects
    with pytest.raises(SparkDsgError, match="semantic label 0, .* pass --label-map"):
        from_spark_dsg(kitchen_and_hall(labelspace=False))


def test_the_public_hydra_apartment_reads_with_its_label_space(tmp_path):
    graph = load_spark_dsg(apartment(tmp_path), APARTMENT_LABELS)
    assert sorted(graph.objects) == ["chair A", "chair B", "chair C", "lamp A", "lamp B", "table A", "table B"]
    assert len(graph.nav.node_xy) == 185 and graph.nav.edges.shape[0] > 185
    view = scene_view(graph, PLANNER_CONFIGS["more"].language)
    assert "unknown_room_0: floor, chair A" in view.text()
    with pytest.raises(SparkDsgError, match="--label-map"):
        load_spark_dsg(apartment(tmp_path))


def test_more_filters_and_plans_on_an_imported_hydra_graph(tmp_path):
    graph = from_spark_dsg(kitchen_and_hall())
    brain = DecisionBrain(keep=["cup A", "table A"], skill="go_to_and_grasp", obj="cup A")
    with FakeOpenAIServer(responder=brain) as server:
        decision = decide(graph, "put the cup in the fridge", [], clients(server.base_url, tmp_path / "cache.sqlite"))
        prompts = [r.body["messages"][-1]["content"] for r in server.requests]
    assert (decision.skill, decision.arguments) == ("go_to_and_grasp", ["kitchen_0", "cup A"])
    assert decision.room_labels == {"region_0": "kitchen", "region_1": "kitchen"}
    assert "cup A [on top of table A]" in decision.filtered_scene and "chair A" not in decision.filtered_scene
    assert "chair A" in decision.scene and decision.regions["kitchen_0"] == "region_0"
    assert len(prompts) == 4 and decision.llm_usage.calls == 4  # two room labels, the filter, the plan
    assert json.loads(decision.model_dump_json())["skill"] == "go_to_and_grasp"
