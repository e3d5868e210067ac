"""Goal instances a description cannot single out (sim.ambiguity), and the descriptions that name
them (sim.descriptions)."""

from __future__ import annotations

import pytest

from more_agent.errors import UserError
from more_agent.sim.ambiguity import ambiguous_scopes, described_scopes
from more_agent.sim.instantiate import instantiate


def test_the_checkout_of_a_store_with_two_is_ambiguous_in_the_papers_words() -> None:
    inst = instantiate("buy_eggs", "grocery_store_cafe", 0, start="task-room", distractors=False, descriptions="paper")
    counters = [o for o in inst.world.objects.values() if o.category == "checkout_counter"]
    assert len(counters) >= 2  # the scene's own furniture, not the task's
    assert inst.description == "put egg A and money on the checkout"  # the paper's text, verbatim
    assert ambiguous_scopes(inst) == ["checkout.n.03_1"]


def test_the_default_description_names_the_goals_checkout_by_its_label() -> None:
    inst = instantiate("buy_eggs", "grocery_store_cafe", 0, start="task-room", distractors=False)
    checkout = inst.labels.label(inst.scope["checkout.n.03_1"])
    assert inst.descriptions == "named" and inst.description.startswith("put egg A and money on the checkout. ")
    assert f"on top of {checkout}" in inst.description and checkout.startswith("checkout_counter ")
    assert ambiguous_scopes(inst) == [] and "checkout.n.03_1" in described_scopes(inst)


def test_a_distractor_of_a_goal_items_category_makes_it_ambiguous_until_named() -> None:
    # bag_groceries: "put egg, apple, orange juice and canned food in a bag"; the store has its own apples.
    paper = instantiate("bag_groceries", seed=0, descriptions="paper")
    apple = paper.scope["apple.n.01_1"]
    assert any(o.category == paper.world.objects[apple].category for o in paper.world.objects.values() if o.name in paper.distractors)
    assert "apple.n.01_1" in ambiguous_scopes(paper)
    named = instantiate("bag_groceries", seed=0)
    assert named.labels.label(apple) in named.description and ambiguous_scopes(named) == []


def test_a_quantifier_over_items_distractors_share_lists_the_instances_it_ranges_over() -> None:
    # boxing_books_up_for_storage: "every book" of the goal is the task's six, not the house's own.
    inst = instantiate("boxing_books_up_for_storage", seed=0)
    books = [inst.labels.label(inst.scope[f"book.n.02_{i}"]) for i in range(1, 7)]
    assert "The book(s) meant are " + ", ".join(books[:-1]) + f" and {books[-1]}." in inst.description
    assert ambiguous_scopes(inst) == []


def test_the_default_description_states_the_goal_conditions_the_papers_text_leaves_out() -> None:
    inst = instantiate("preparing_lunch_box", seed=0)
    fridge = inst.labels.label(inst.scope["electric_refrigerator.n.01_1"])
    assert f". Close {fridge} when done." in inst.description
    assert "Close" not in instantiate("preparing_lunch_box", seed=0, descriptions="paper").description
    # the cabinets a forall wants closed are the task's two, not the kitchen's others: a reader closing every
    # cabinet it looked into ran past the goal (putting_dishes_away_after_cleaning seed 0 left one open)
    dishes = instantiate("putting_dishes_away_after_cleaning", seed=0)
    first, other = (dishes.labels.label(dishes.scope[s]) for s in ("cabinet.n.01_1", "cabinet.n.01_*"))
    assert f"Close {first} and {other} when done." in dishes.description and first != other


def test_an_unknown_description_mode_names_the_valid_ones() -> None:
    with pytest.raises(UserError, match="unknown description mode 'papr'; closest: paper"):
        instantiate("buy_eggs", seed=0, descriptions="papr")


def test_a_scope_the_description_names_is_not_ambiguous() -> None:
    inst = instantiate("buy_eggs", "grocery_store_cafe", 0, start="task-room", distractors=False, descriptions="paper")
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


def test_closing_every_cabinet_and_a_cabinet_the_description_names_are_not_ambiguous() -> None:
    # putting_dishes_away_after_cleaning: every plate in one cabinet ("$cabinet.n.01_1", an ``exists``
    # the description names a member of), every cabinet closed (a forall over furniture: close them all).
    inst = instantiate("putting_dishes_away_after_cleaning", seed=1, descriptions="paper")
    assert not any(s.startswith("cabinet") for s in ambiguous_scopes(inst))


def test_a_generated_description_names_the_floors_it_mentions() -> None:
    # "put every bag of rubbish on top of the garden floor": the garden's floor, not the living room's
    # the bags lie on (the planner took any floor for it, and called done at its first step).
    inst = instantiate("taking_trash_outside", seed=0, start="task-room", distractors=False)
    assert inst.definition.paper_description is None and "the garden floor" in inst.description
    floors = {s for s in inst.scope if s.startswith("floor.")}
    assert {s for s in floors if inst.label(s) == "the garden floor"} == floors & described_scopes(inst)
    assert len(floors) == 2 and len(floors & described_scopes(inst)) == 1
