"""Goal instances a description cannot single out (sim.ambiguity)."""

from __future__ import annotations

from more_agent.sim.ambiguity import ambiguous_scopes, described_scopes
from more_agent.sim.instantiate import instantiate


def test_the_checkout_of_a_store_with_two_is_ambiguous() -> None:
    inst = instantiate("buy_eggs", "grocery_store_cafe", 0, start="task-room", distractors=False)
    counters = [o for o in inst.world.objects.values() if o.category == "checkout_counter"]
    assert len(counters) >= 2  # the scene's own furniture, not the task's
    assert ambiguous_scopes(inst) == ["checkout.n.03_1"]


def test_a_scope_the_description_names_is_not_ambiguous() -> None:
    inst = instantiate("buy_eggs", "grocery_store_cafe", 0, start="task-room", distractors=False)
    # "put $egg.n.02_1 and money on the checkout": the egg is named; the money and the eggs'
    # look-alikes are task objects only.
    assert "egg.n.02_1" in described_scopes(inst)
    assert "egg.n.02_1" not in ambiguous_scopes(inst)
    assert "money.n.01_1" not in ambiguous_scopes(inst)


def test_furniture_of_the_category_does_not_make_an_item_to_move_ambiguous() -> None:
    # packing_car_for_trip puts laptop_1 in the car; the scene's own laptop is furniture, which a
    # reader of the goal knows stays put: the task's laptop is the one that can be moved.
    inst = instantiate("packing_car_for_trip", seed=0, start="task-room", distractors=False)
    fixed = [o for o in inst.world.objects.values() if o.category == "laptop" and not o.movable]
    assert fixed
    assert "laptop.n.01_1" not in ambiguous_scopes(inst)


def test_a_quantified_goal_scope_is_not_ambiguous() -> None:
    # putting_dishes_away_after_cleaning: every plate in some cabinet, every cabinet closed.
    inst = instantiate("putting_dishes_away_after_cleaning", seed=0, start="task-room", distractors=False)
    assert not any(s.startswith("cabinet") for s in ambiguous_scopes(inst))


def test_a_generated_description_names_the_floors_it_mentions() -> None:
    # "put every bag of rubbish on top of the garden floor": the garden's floor, not the living room's
    # the bags lie on (the planner took any floor for it, and called done at its first step).
    inst = instantiate("taking_trash_outside", seed=0, start="task-room", distractors=False)
    assert inst.definition.paper_description is None and "the garden floor" in inst.description
    floors = {s for s in inst.scope if s.startswith("floor.")}
    assert {s for s in floors if inst.label(s) == "the garden floor"} == floors & described_scopes(inst)
    assert len(floors) == 2 and len(floors & described_scopes(inst)) == 1
