"""The ``grounded`` planner: an ideal reader of the goal, acting only through what the robot observes.

It stands in for a language model that understands the task perfectly. It knows the task's goal in
BDDL form and its description (:class:`more_agent.goal.TaskGoal`, computed by the runner), and the world only through
the same embodiment, scene graph and subpolicies as MORE: no world state, no object positions it
has not seen, no goal checks. What it reaches is therefore the ceiling that perception, mapping,
the scene graph and the subpolicies put on any language planner (``benchmarks/pipeline_ceiling.py``).

Every step (MPC style) it rebuilds the scene graph and:

1. binds each goal scope to an observed instance: the label the description names, else the
   nearest unbound instance of a category that counts as the scope's synset; bindings stay;
2. evaluates every literal of the goal option on what it believes (observed open state and spatial
   relations, its own placements on floors, objects whose box reaches the ground on their room's
   floor, and what rests on a loose item lying on a floor: ``belief.floor_beneath``) and calls ``done``
   when all hold;
3. otherwise acts for the first literal (oracle order: opening, removals, placements with contents
   before their containers move, closing, the robot's own position) whose objects it knows: open a
   closed container before placing inside, grasp, place (on a floor the description names only once
   a region of that room type is known, or the region where it found what the description says stays
   on that floor: until then it searches), put down what the hand holds but
   does not need (on the floor, or on low standing furniture when the goal wants it off that floor);
4. when a needed object is unseen: opens the closed containers of the robot's room (openables that
   hold things, not a laptop; three in a row at most while there is a room to explore; none while a
   room of a likelier tier is left to explore, nor when only furniture is missing; in a room of the last
   tier, none while any room or closed door is left), explores first the
   rooms of the types expected to hold the most of the missing objects (where the missing items are
   kept, from bddl's activity corpus, the task's own activity left out:
   :mod:`more_agent.planners.whereabouts`; where the BEHAVIOR-1K inventories list the missing
   furniture's kind; outweighed by what is known: the room the description says an object stays in,
   and the room types where the task's items were found or are said to stay, for what is set out with
   them): likely types, then unknown ones, then unlikely ones, whose turn waits for the closed doors; a
   room on the other side of the walls from the likeliest type (a garden when it is indoors) ranks after
   the unlikely ones, a likely one next, an unlikely one last; then the room most likely to hold the
   missing furniture (the share of the room type's listed objects), a room where the task's items were
   found (they are set out together) before the others, then the room whose frontiers show the most
   unseen floor, the nearest; containers are opened likeliest first (a kind's evidence spread over the
   room's containers of that kind),
   those no missing item of the goal fits in or is ever kept in last; each explore drives to the frontiers farthest
   from the robot's path, of those to the ones with the most unseen floor in sensor range
   (information gain on the robot's own occupancy map). Before the search leaves the rooms where
   the task's items were found (or when their explores reveal nothing new) it drives to their
   tables, shelves and counters it has not been near, where small items show only from close by,
   and opens their closed containers (neither for missing furniture). A room whose last two
   explores revealed nothing new (no object, under 10 m² of floor not mapped before) yields to the other containers and closed doors; the planner
   gives up with ``done`` when nothing is left to try.

An approach that reports a closed door in its way (``ActionResult.blocking``, the door's label) has that
door opened next, the hand freed first, as the oracle does. An action that fails twice the same way (its
typed reason and the door in the way) is not repeated: its target is dropped from the bindings (another
instance is taken) or, for a named instance, the planner gives up. An object that cannot be picked up is dropped at once (a category can be both: a store's
cartons are furniture, a task's are items). Regions are labelled with the room type their furniture fits best
(:mod:`more_agent.planners.room_types`).

The package: what the planner has learnt is a :class:`~.belief.Belief` (``belief.py``), updated after
each observation and each executed step; the next step is chosen by functions of the belief, the
step's :class:`~.situation.Situation` and the goal's :class:`~.agenda.Agenda` (``choose.py``, the
search in ``search.py``, the steps on objects and floors in ``steps.py``, the literals in
``literals.py``), which change nothing but the bindings (and forget a door in the way once it is open):
a goal scope is bound the first time a choice needs it (``belief.bind``) and stays bound. ``planner.py``
holds the planner protocol around them.
"""

from more_agent.planners.grounded.planner import GroundedPlanner

__all__ = ["GroundedPlanner"]
