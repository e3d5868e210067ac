"""Goal checks through bddl: per-conjunct status, progress over the best ground option, quantifiers."""

from __future__ import annotations

from pathlib import Path

import pytest

from more_agent.sim.goals import GoalChecker, Literal
from more_agent.sim.instantiate import TaskInstance, instantiate_in_scene
from more_agent.sim.scene import load_scene

KITCHEN = Path(__file__).parent.parent / "fixtures" / "tasks_kitchen_scene.json"


def _inst(task: str, seed: int = 0) -> TaskInstance:
    return instantiate_in_scene(task, load_scene(KITCHEN), seed=seed)


def test_conjuncts_and_progress_follow_the_world() -> None:
    inst = _inst("putting_shopping_away")
    checker = GoalChecker(inst)
    status = checker.check()
    assert not status.all_met and status.progress == 0.0
    assert len(status.conditions) == 5 and not any(c.satisfied for c in status.conditions)
    fridge, cabinet = inst.scope["electric_refrigerator.n.01_1"], inst.scope["cabinet.n.01_1"]
    assert "(inside pack__of__ground_beef_1 fridge_0)" in [c.text for c in status.conditions]
    moves = [("pack__of__ground_beef_1", fridge), ("cup__of__yogurt_1", fridge), ("canned_food_1", cabinet),
             ("box__of__cereal_1", cabinet), ("bottle__of__cooking_oil_1", cabinet)]
    for k, (item, target) in enumerate(moves, start=1):
        inst.world.place(item, target, "inside")
        status = checker.check()
        assert status.progress == pytest.approx(k / 5)
        done = {c.text for c in status.conditions if c.satisfied}
        assert f"(inside {item} {target})" in done
    assert status.all_met
    lits = checker.ground_literals(status.option_index)
    assert Literal("inside", ("canned_food_1", cabinet)) in lits


def test_exists_forall_and_negation() -> None:
    inst = _inst("putting_dishes_away_after_cleaning")
    world = inst.world
    checker = GoalChecker(inst)
    plates = sorted(o.name for o in world.items() if o.category == "plate")
    assert len(plates) == 8
    cabinets = sorted(o.name for o in world.objects.values() if o.category == "bottom_cabinet")
    for p in plates[:4]:
        world.place(p, cabinets[0], "inside")
    for p in plates[4:]:
        world.place(p, cabinets[1], "inside")
    assert not checker.check().all_met  # exists one cabinet holding every plate: not yet
    for p in plates[4:]:
        world.place(p, cabinets[0], "inside")
    world.set_open(cabinets[0], True)
    status = checker.check()
    assert not status.all_met  # the cabinet must be closed
    assert any("(not (open" in c.text and not c.satisfied for c in status.conditions)
    world.set_open(cabinets[0], False)
    status = checker.check()
    assert status.all_met and status.progress == 1.0


def test_forpairs() -> None:
    inst = _inst("line_kitchen_shelves")
    world, checker = inst.world, GoalChecker(inst)
    linings = sorted(o.name for o in world.items() if o.category.startswith("lining") or o.synset == "lining.n.01")
    cabinets = [inst.scope["cabinet.n.01_1"], inst.scope["cabinet.n.01_2"]]
    world.place(linings[0], cabinets[0], "inside")
    world.place(linings[1], cabinets[0], "inside")
    assert not checker.check().all_met  # both in one cabinet: not a pairing
    world.place(linings[1], cabinets[1], "inside")
    assert checker.check().all_met


def test_ontop_follows_stacks_but_not_containers() -> None:
    inst = _inst("putting_shopping_away")
    world = inst.world
    from more_agent.sim.predicates import is_ontop

    world.place("sack_1", "breakfast_table_0", "ontop")
    world.place("canned_food_1", "sack_1", "ontop")
    assert is_ontop(world, "canned_food_1", "breakfast_table_0")
    world.place("canned_food_1", "sack_1", "inside")
    assert not is_ontop(world, "canned_food_1", "breakfast_table_0")
    assert world.is_inside("canned_food_1", "sack_1")


def test_furniture_stands_on_its_own_rooms_floor_only() -> None:
    from more_agent.sim.predicates import is_ontop

    world = _inst("putting_shopping_away").world
    table = world.get("breakfast_table_0")
    other_rooms = [r.id for r in world.scene.rooms if r.id != table.room]
    assert is_ontop(world, "breakfast_table_0", f"floor_{table.room}")
    assert other_rooms and not is_ontop(world, "breakfast_table_0", f"floor_{other_rooms[0]}")


def test_goal_without_ground_option_is_a_clear_error() -> None:
    from more_agent.sim.goals import GoalError
    from more_agent.sim.instantiate import instantiate

    with pytest.raises(GoalError, match="no ground option for the goal of make_a_bake_sale_stand_stall"):
        GoalChecker(instantiate("make_a_bake_sale_stand_stall"))


def test_check_another_world() -> None:
    inst, other = _inst("putting_shopping_away"), _inst("putting_shopping_away")
    checker = GoalChecker(inst)
    other.world.place("canned_food_1", other.scope["cabinet.n.01_1"], "inside")
    assert checker.check(other.world).progress == pytest.approx(0.2)
    assert checker.check(inst.world).progress == 0.0


def test_options_never_relate_an_object_to_itself() -> None:
    """stacking_wood's forall over logs offers ``ontop`` each log: bddl's 20 options all held ``(ontop log_1 log_1)``,
    and the first without it put log_1 on log_2 and log_2 on log_1."""
    from more_agent.sim.instantiate import instantiate

    checker = GoalChecker(instantiate("stacking_wood"))
    assert checker.n_options == 20
    options = [checker.ground_literals(i) for i in range(checker.n_options)]
    assert all(lit.negated or len(set(lit.args)) == len(lit.args) for option in options for lit in option)
    placed = [{lit.args for lit in option if lit.predicate == "ontop" and not lit.negated} for option in options]
    assert not any((b, a) in pairs for pairs in placed for a, b in pairs)  # nor log_1 on log_2 on log_1
    assert all(any(lit.args[1].startswith("log_") for lit in option) for option in options)  # logs on logs kept


@pytest.mark.parametrize("task", ["putting_shopping_away", "putting_dishes_away_after_cleaning"])
def test_options_are_bddls_where_none_relates_an_object_to_itself(task: str) -> None:
    from bddl.activity import get_goal_conditions, get_ground_goal_state_options

    from more_agent.sim.goals import literal_from_parsed

    inst = _inst(task)
    checker = GoalChecker(inst)
    conds, scope = inst.definition.conditions, inst.scope_objects()
    goal = get_goal_conditions(conds, checker.backend, dict(scope))
    bddl_options = get_ground_goal_state_options(conds, checker.backend, dict(scope), goal)
    ours = [checker.ground_literals(i) for i in range(checker.n_options)]
    assert ours == [[literal_from_parsed(head.body, scope) for head in option] for option in bddl_options]
    assert checker.objects >= {arg for option in ours for lit in option for arg in lit.args}  # any option's objects


def test_the_objects_a_goal_may_use_are_every_instance_its_quantifiers_range_over() -> None:
    """putting_out_condiments wants any four of seven knives on the table; bddl keeps 20 ground options, which
    name six. A robot that carried the seventh used no wrong instance (the failure causes read this)."""
    from more_agent.sim.instantiate import instantiate

    checker = GoalChecker(instantiate("putting_out_condiments", seed=0))
    named = {arg for i in range(checker.n_options) for lit in checker.ground_literals(i) for arg in lit.args}
    knives = {name for name in checker.objects if name.startswith("table_knife_")}
    assert len(knives) == 7 and len(knives & named) == 6
