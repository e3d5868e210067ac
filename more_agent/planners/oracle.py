"""The oracle planner: privileged access to the BDDL goal and the full world, acting through the magic actions.

It proves instantiated tasks feasible and is the upper-bound row of results tables. At reset it
picks the ground goal option it can best achieve (fewest literals it cannot handle, then fewest
unmet), orders its literals (``order_literals``) and then, MPC-style, re-reads the world before
every step and issues the next subpolicy for the first unmet literal:

- ``inside(a, b)`` / ``ontop(a, b)``: reveal ``a`` and ``b`` (open what hides them), open ``b`` when
  placing inside, open a closed door between them, then ``go_to_and_grasp a`` and
  ``go_to_and_place_{inside,ontop} b``; contents go in before their container moves.
- ``not inside / not ontop``: grasp ``a`` and put it on the floor where the robot stands.
- ``open(x)`` / ``not open(x)``: ``go_to_and_open`` / ``go_to_and_close`` (closing comes last).
- ``ontop(robot, floor)``: ``navigate_to`` that room, at the very end.

A closed door reported on the way is opened (after putting down what the hand holds). Literals
over other predicates are skipped and named in the final ``done``; an action that fails twice
makes the oracle give up with a ``done`` whose ``gave_up`` says what failed and why.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Collection

from more_agent.goal import ROBOT_NAME, Literal
from more_agent.planners.base import DONE, EpisodeContext, Step, StepTrace
from more_agent.planners.goal_order import ORACLE_PREDICATES, PUT_DOWN_MAX_TOP_M, as_placed, order_literals
from more_agent.planners.policies import Embodiment
from more_agent.records import FailureReason, LLMUsage
from more_agent.robot import ActionResult
from more_agent.scene_graph import SceneGraph
from more_agent.sim.actions import approach_rounds, distance_to_footprint
from more_agent.sim.env import ACTION_TYPES
from more_agent.sim.goals import GoalChecker, PrivilegedContext, literal_holds
from more_agent.sim.navgrid import blocking_door, nav_grid
from more_agent.sim.paths import reaches
from more_agent.sim.world import World, WorldObject
from more_agent.skills import skill_named
from more_agent.vocabulary import RELATIONS

MAX_FAILURES_PER_ACTION = 2
"""The oracle gives up once the same action has failed this many times."""


def unsupported_reason(world: World, lit: Literal) -> str | None:
    """Why the oracle cannot achieve ``lit``, or None when it can."""
    if lit.predicate not in ORACLE_PREDICATES:
        return f"predicate {lit.predicate!r} is not a rearrangement"
    missing = [a for a in lit.args if a != ROBOT_NAME and a not in world.objects]
    if missing:
        return f"{', '.join(missing)} is not an object of the world"
    if lit.predicate == "open":
        return None if world.get(lit.args[0]).openable else f"{lit.args[0]} is not openable"
    subject, target = lit.args
    if subject == target:
        return "an object cannot be in or on itself"
    if subject == ROBOT_NAME:
        ok = lit.predicate == "ontop" and not lit.negated and world.get(target).kind == "floor"
        return None if ok else "the robot can only be asked to stand in a room"
    if not world.get(subject).movable:
        return f"{subject} cannot be moved"
    return None


def merge_placements(world: World, literals: list[Literal]) -> list[Literal]:
    """Drop duplicates and resolve one subject with several placements through the stack they imply.

    Each subject's first placement onto / into an item is its primary one: ``ontop(a, b)`` with
    ``b`` an item. Another ``ontop(a, c)`` (or ``inside(a, c)``) then holds once ``b`` goes onto
    (into) ``c``, since the relations follow stacks, so it becomes ``ontop(b, c)`` (``inside(b, c)``);
    likewise ``inside(a, b)`` with ``inside(a, c)`` becomes ``inside(b, c)``. Placing ``a`` on ``c``
    directly would undo the primary literal.
    """

    def placement(lit: Literal) -> bool:
        return lit.predicate in RELATIONS and not lit.negated and lit.args[0] != ROBOT_NAME

    primary: dict[str, Literal] = {}
    for lit in literals:
        if placement(lit) and lit.args[0] not in primary and world.get(lit.args[1]).movable:
            primary[lit.args[0]] = lit
    out: list[Literal] = []
    for lit in literals:
        via = primary.get(lit.args[0]) if placement(lit) else None
        if via is not None and via.args[1] != lit.args[1] and (via.predicate == "ontop" or lit.predicate == "inside"):
            derived = Literal(lit.predicate, (via.args[1], lit.args[1]))
            lit = derived if derived.args[0] != derived.args[1] else lit
        if lit not in out:
            out.append(lit)
    return out


def placements(goals: GoalChecker, option: int) -> list[Literal]:
    """The ground literals of goal option ``option`` as the skills achieve them (``goal_order.as_placed``)."""
    return [as_placed(lit) for lit in goals.ground_literals(option)]


def choose_option(goals: GoalChecker, world: World, exclude: Collection[int] = frozenset()) -> int | None:
    """The ground goal option (not in ``exclude``) with the fewest literals the oracle cannot achieve, then the fewest unmet."""

    def cost(i: int) -> tuple[int, int, int]:
        lits = placements(goals, i)
        unsupported = sum(unsupported_reason(world, lit) is not None for lit in lits)
        unmet = sum(unsupported_reason(world, lit) is None and not literal_holds(world, lit) for lit in lits)
        return unsupported, unmet, i

    candidates = [i for i in range(goals.n_options) if i not in exclude]
    return min(candidates, key=cost) if candidates else None


class OraclePlanner:
    """Solves a task from the goal and full state through ``go_to_and_<verb>`` subpolicies."""

    name = "oracle"
    llm: str | None = None
    """The oracle plans with no LLM; the registry's ``llm`` argument is ignored."""

    def __init__(self, llm: str | None = None) -> None:
        del llm
        self._privileged: PrivilegedContext | None = None

    def grant(self, privileged: PrivilegedContext) -> None:
        """Receive the episode's world and goal checker (the runner calls it before ``reset``)."""
        self._privileged = privileged

    def reset(self, context: EpisodeContext) -> None:
        """Choose the goal option and order its literals."""
        if self._privileged is None:
            raise RuntimeError("the oracle plans from the world: grant() it a PrivilegedContext before reset()")
        self._world = self._privileged.world
        self._goals = self._privileged.goals
        self._observed = self._privileged.observed
        """Objects it acted on or revealed by opening (the runner adds them to what the camera saw)."""
        self._tried: set[int] = set()
        self._adopt_next_option()
        self._door: str | None = None
        self._intent: Literal | None = None
        """The literal the held item was grasped for."""
        self._failures: Counter[tuple[str, tuple[str, ...]]] = Counter()
        self._last_failure: dict[tuple[str, tuple[str, ...]], ActionResult] = {}
        """Per action, its last failure: compared by typed reason and blocking door; its feedback explains a give-up."""
        self._body = Embodiment(context.robot, sensing=context.sensing)
        self._trace_graphs = context.trace_graphs
        self._graph: SceneGraph | None = None
        """The step's scene graph, built only for the trace (the oracle plans from the world)."""
        self._body.start(sense_first=False)  # every trajectory starts with a full turn in place (paper S.3)

    def _adopt_next_option(self) -> bool:
        """Work on the best ground option not tried yet; False when every option has been tried."""
        option = choose_option(self._goals, self._world, exclude=self._tried)
        if option is None:
            return False
        self._tried.add(option)
        literals = placements(self._goals, option)
        self._skipped = {lit: why for lit in literals if (why := unsupported_reason(self._world, lit)) is not None}
        supported = [lit for lit in literals if lit not in self._skipped]
        self._literals = order_literals(merge_placements(self._world, supported))
        return True

    def observe(self) -> None:
        """Sense one frame from where the robot stands. The oracle plans from the world itself, but what
        its camera sees is what it observed (for rTP), what ``--save-frames`` writes and what the
        ``--save-graph`` scene graph is built from."""
        self._body.sense()
        self._graph = self._body.build() if self._trace_graphs else None

    def step_trace(self) -> StepTrace:
        """The scene graph of what the camera saw, when the episode asked for graphs."""
        return StepTrace(graph=self._graph)

    def llm_usage(self) -> LLMUsage:
        """The oracle uses no LLM."""
        return LLMUsage()

    # -- deciding -----------------------------------------------------------------------------
    def decide(self) -> Step:
        """``done`` when the goal holds (or nothing more can be done), else the next subpolicy."""
        if self._goals.check(self._world).all_met:
            return Step(DONE, note="all goal conditions hold")
        pending = [lit for lit in self._literals if not literal_holds(self._world, lit)]
        while not pending:
            # bddl's ground options can be partly infeasible (e.g. '(ontop log_1 log_1)'): the next may finish the job.
            explanation = self._explain_unmet()
            if not self._adopt_next_option():
                return Step(DONE, gave_up=explanation)
            pending = [lit for lit in self._literals if not literal_holds(self._world, lit)]
        action = self._door_action() or self._next(pending)
        key = (action.name, action.arguments)
        if self._failures[key] >= MAX_FAILURES_PER_ACTION:
            why = self._last_failure[key].feedback
            note = (
                f"oracle gave up: {action.name} {' '.join(action.arguments)} failed {self._failures[key]} times ({why})"
            )
            return Step(DONE, gave_up=note)
        return action

    def _explain_unmet(self) -> str:
        if self._skipped:
            return "goal literals the oracle cannot achieve: " + "; ".join(
                f"{lit.text} ({why})" for lit, why in self._skipped.items()
            )
        return "every literal of the chosen goal option holds, yet the goal check fails"

    def _door_action(self) -> Step | None:
        """Open the door reported as blocking, first freeing the hand."""
        if self._door is None or self._world.get(self._door).is_open:
            self._door = None
            return None
        if self._world.robot.held is not None:
            return self._put_down()
        return Step("go_to_and_open", (self._door,), note="a closed door blocks the way")

    def _next(self, pending: list[Literal]) -> Step:
        held = self._world.robot.held
        if held is not None:
            # Finish what the hand holds: the placement it was grasped for first, else any that is ready.
            intent = [self._intent] if self._intent in pending else []
            for lit in intent + pending:
                if lit.args[0] == held and not lit.negated and lit.predicate != "open":
                    if self._blocker(lit.args[1], lit.predicate) is None:
                        return self._act(f"go_to_and_place_{lit.predicate}", lit.args[1], lit)
        return self._step_for(pending[0])

    def _step_for(self, lit: Literal) -> Step:
        world, held = self._world, self._world.robot.held
        if lit.predicate == "open":
            target = lit.args[0]
            hider = world.enclosing_closed_container(target)
            if held is not None:
                return self._put_down()
            if hider is not None:
                return self._act("go_to_and_open", hider.name, lit)
            return self._act("go_to_and_close" if lit.negated else "go_to_and_open", target, lit)
        subject, target = lit.args
        if subject == ROBOT_NAME:
            return self._act("navigate_to", target, lit)
        if lit.negated:
            if held == subject:
                return self._put_down()
            return self._put_down() if held is not None else self._fetch(subject, lit)
        if any(d.name == target for d in world.descendants(subject)):
            # The target rests on / in the subject: take it off first.
            if held is not None:
                return self._put_down()
            return self._act("go_to_and_grasp", target, lit)
        blocker = self._blocker(target, lit.predicate)
        if held == subject:
            return self._act(f"go_to_and_place_{lit.predicate}", target, lit) if blocker is None else self._put_down()
        if held is not None:
            return self._put_down()
        if blocker is not None:
            return self._act("go_to_and_open", blocker, lit)
        door = self._door_between(subject, target)
        if door is not None:
            return self._act("go_to_and_open", door, lit)
        return self._fetch(subject, lit)

    def _act(self, name: str, arg: str, lit: Literal) -> Step:
        return Step(name, (arg,), note=f"for {lit.text}")

    def _fetch(self, subject: str, lit: Literal) -> Step:
        hider = self._world.enclosing_closed_container(subject)
        if hider is not None:
            return self._act("go_to_and_open", hider.name, lit)
        self._intent = lit
        return self._act("go_to_and_grasp", subject, lit)

    def _blocker(self, target: str, predicate: str) -> str | None:
        """What must be opened before something can be placed in / on ``target``."""
        hider = self._world.enclosing_closed_container(target)
        if hider is not None:
            return hider.name
        obj = self._world.get(target)
        if predicate == "inside" and obj.openable and not obj.is_open:
            return target
        return None

    def _door_between(self, subject: str, target: str) -> str | None:
        """A closed door between where ``subject`` is and where ``target`` can be reached from."""
        start = next((p for poses in approach_rounds(self._world, subject) for p in poses), None)
        goals = [p for poses in approach_rounds(self._world, target) for p in poses]
        if start is None or not goals or reaches(nav_grid(self._world), start, goals):
            return None
        return blocking_door(self._world, start, goals)

    def _put_down(self) -> Step:
        """Free the hand: put the held item down where it breaks no goal and the robot can get to.

        In order: the floor of the robot's room, the top of the nearest furniture in that room, the
        nearest other floor; floors the item must not be on (a ``not ontop`` goal) and spots where
        putting down already failed are skipped.
        """
        world = self._world
        held = world.robot.held
        avoid = {
            lit.args[1] for lit in self._literals if lit.negated and lit.predicate == "ontop" and lit.args[0] == held
        }
        room = world.room_at(world.robot.x, world.robot.y)

        def rank(o: WorldObject) -> tuple[int, float]:
            tier = 0 if o.kind == "floor" and o.room == room else 1 if o.room == room else 2
            return tier, distance_to_footprint(world, o.name)

        spots = sorted(
            (
                o
                for o in world.objects.values()
                if o.name not in avoid
                and (
                    o.kind == "floor"
                    or (
                        o.kind == "furniture"
                        and o.room == room
                        and o.top <= PUT_DOWN_MAX_TOP_M
                        and not (o.openable and not o.is_open)
                    )
                )
            ),
            key=rank,
        )
        actions = [Step("go_to_and_place_ontop", (o.name,), note="free the hand") for o in spots]
        return next((a for a in actions if self._failures[(a.name, a.arguments)] == 0), actions[0])

    # -- acting -------------------------------------------------------------------------------
    def execute(self, action: Step) -> ActionResult:
        """Run a subpolicy as one magic action of the env; remember failures and blocking doors."""
        world = self._world
        result = self._body.act(world_action(action.name), *action.arguments)
        if action.is_done:
            return result
        (arg,) = action.arguments
        if result.ok:
            self._observed.add(arg)
            if action.name == "go_to_and_open":
                self._observed.update(o.name for o in world.shown_by_opening(arg))
        else:
            key = (action.name, action.arguments)
            # A different failure (another reason, another door in the way, even one not yet seen)
            # is progress; the same one twice is not.
            last = self._last_failure.get(key)
            same = last is not None and (last.reason, last.blocking) == (result.reason, result.blocking)
            self._failures[key] = self._failures[key] + 1 if same else 1
            self._last_failure[key] = result
            if result.reason is FailureReason.PATH_BLOCKED_BY_DOOR:
                self._door = result.blocking
        return result


def world_action(name: str) -> str:
    """The env action type that runs an oracle action: ``navigate_to`` and ``done`` are action types
    themselves, a skill (``go_to_and_grasp``) runs its world action from the skill table."""
    if name in ACTION_TYPES:
        return name
    action = skill_named(name).world_action
    if action is None:
        raise ValueError(f"oracle cannot execute {name!r}: it acts on the world, not on a map")
    return action
