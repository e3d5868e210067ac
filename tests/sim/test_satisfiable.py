"""A goal no state meets: the 0-1 program agrees with bddl's own evaluation under every truth assignment."""

from __future__ import annotations

import copy
import itertools
from pathlib import Path
from typing import Any

import pytest
from bddl.activity import get_goal_conditions
from bddl.backend_abc import BDDLBackend
from bddl.logic_base import BinaryAtomicFormula, UnaryAtomicFormula
from bddl.parsing import scan_tokens

from more_agent.sim.goals import GoalChecker
from more_agent.sim.instantiate import TaskInstance, instantiate_in_scene
from more_agent.sim.satisfiable import satisfiable
from more_agent.sim.scene import load_scene

KITCHEN = Path(__file__).parent.parent / "fixtures" / "tasks_kitchen_scene.json"
LININGS = "(?l - lining.n.01)"
CABINETS = "(?c - cabinet.n.01)"


@pytest.fixture(scope="module")
def shelves() -> TaskInstance:
    """Two linings and two cabinets in scope: few enough atoms to try every truth assignment."""
    return instantiate_in_scene("line_kitchen_shelves", load_scene(KITCHEN), seed=0)


class _Truth(BDDLBackend):
    """A bddl backend whose atoms read a truth assignment, not a world."""

    def __init__(self) -> None:
        self.true: set[tuple[object, ...]] = set()
        self.asked: set[tuple[object, ...]] = set()

    def get_predicate_class(self, predicate_name: str) -> type:
        base = UnaryAtomicFormula if predicate_name == "open" else BinaryAtomicFormula

        def _evaluate(formula: Any, *args: object) -> bool:
            key = (predicate_name, *args)
            formula.backend.asked.add(key)
            return key in formula.backend.true

        def _sample(formula: Any, *args: object) -> None:
            raise NotImplementedError

        return type(f"Truth_{predicate_name}", (base,), {"STATE_NAME": predicate_name, "_evaluate": _evaluate,
                                                        "_sample": _sample})


def _by_enumeration(inst: TaskInstance, text: str) -> tuple[bool, list[Any]]:
    """Whether bddl's evaluation is true under some assignment of the goal's atoms, and the compiled goal."""
    conds, backend = copy.copy(inst.definition.conditions), _Truth()
    conds.parsed_goal_conditions = [scan_tokens(string=text)]
    goal = get_goal_conditions(conds, backend, dict(inst.scope_objects()), generate_ground_options=False)
    assert all(head.evaluate() is not None for head in goal)  # fills backend.asked
    atoms = sorted(backend.asked, key=repr)
    assert len(atoms) <= 14
    for values in itertools.product((False, True), repeat=len(atoms)):
        backend.true = {a for a, v in zip(atoms, values, strict=True) if v}
        if all(head.evaluate() for head in goal):
            return True, goal
    return False, goal


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("(forpairs (?l - lining.n.01) (?c - cabinet.n.01) (inside ?l ?c))", True),
        (f"(and (forn (2) {LININGS} (open ?l)) (not (open lining.n.01_1)))", False),
        (f"(forn (3) {LININGS} (open ?l))", False),  # exactly three of two
        (f"(and (exists {CABINETS} (open ?c)) (forall {CABINETS} (not (open ?c))))", False),
        ("(imply (open cabinet.n.01_1) (not (open cabinet.n.01_1)))", True),
        # stacking_wood's shape: each lining open or inside cabinet 1, exactly one open, none inside
        (f"(and (forall {LININGS} (or (open ?l) (inside ?l cabinet.n.01_1))) (forn (1) {LININGS} (open ?l)) "
         f"(forn (0) {LININGS} (inside ?l cabinet.n.01_1)))", False),
        (f"(and (forall {LININGS} (or (open ?l) (inside ?l cabinet.n.01_1))) (forn (1) {LININGS} (open ?l)))", True),
        (f"(and (fornpairs (2) {LININGS} {CABINETS} (inside ?l ?c)) (not (inside lining.n.01_1 cabinet.n.01_2)))",
         True),
        (f"(and (forpairs {LININGS} {CABINETS} (inside ?l ?c)) (forall {LININGS} (not (inside ?l cabinet.n.01_1))))",
         False),
    ],
)
def test_the_program_agrees_with_bddl_under_every_assignment(shelves: TaskInstance, text: str, expected: bool) -> None:
    enumerated, goal = _by_enumeration(shelves, text)
    assert enumerated is expected  # the case is what it says
    assert satisfiable(goal) is expected


def test_stacking_woods_goal_is_unsatisfiable_and_one_more_log_allowed_is_not() -> None:
    from more_agent.sim.instantiate import instantiate

    inst = instantiate("stacking_wood")
    assert not GoalChecker(inst).satisfiable
    every_log, on_the_table, on_a_log = inst.definition.conditions.parsed_goal_conditions
    relaxed = [every_log, ["forn", ["4"], *on_the_table[2:]], on_a_log]
    assert GoalChecker(inst, goal=relaxed).satisfiable  # four on the table, two on a log: six
