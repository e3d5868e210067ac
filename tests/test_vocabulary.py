"""The shared vocabulary and the robot's spec are the ones every layer uses."""

from __future__ import annotations

from typing import get_args

from more_agent.planners.policies.embodiment import PolicyConfig
from more_agent.planners.room_types import room_type_counts
from more_agent.robot_spec import ROBOT
from more_agent.sim import actions, camera, packing
from more_agent.sim.navgrid import DEFAULT_NAV
from more_agent.vocabulary import RELATIONS, ROOM_TYPES, Relation, room_type, scope_synset


def test_room_types_are_the_inventorys() -> None:
    assert list(ROOM_TYPES) == sorted(room_type_counts())


def test_room_type_of_an_id() -> None:
    assert room_type("living_room_0") == "living_room"


def test_relations_match_their_type() -> None:
    assert RELATIONS == get_args(Relation)


def test_simulator_and_planners_use_the_robot_spec() -> None:
    assert DEFAULT_NAV.robot_radius_m == ROBOT.radius_m
    assert actions.REACH_M == ROBOT.reach_m and packing.REACH_TOP_M == ROBOT.reach_top_m
    assert camera.Camera().hfov_deg == ROBOT.camera.hfov_deg and camera.IMAGE_SIZE == ROBOT.camera.image_size
    assert PolicyConfig().plan_inflation_m > ROBOT.radius_m


def test_scope_synset_strips_an_instance_suffix_and_keeps_a_quantified_variable() -> None:
    """A scope ('apple.n.01_1'), bddl's wildcard scope of an inroom requirement ('cabinet.n.01_*') and a goal's
    quantified variable ('?bottle__of__catsup.n.01', whose synset itself holds underscores)."""
    assert scope_synset("apple.n.01_1") == scope_synset("?apple.n.01_12") == "apple.n.01"
    assert scope_synset("cabinet.n.01_*") == "cabinet.n.01"
    assert scope_synset("?bottle__of__catsup.n.01") == scope_synset("bottle__of__catsup.n.01_3") == "bottle__of__catsup.n.01"
