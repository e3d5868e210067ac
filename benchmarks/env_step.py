"""What stepping the world through the Gymnasium env costs the agent: one JSON object.

``python benchmarks/env_step.py [--scene Rs_int] [--steps 20000]``

The Embodiment makes every low-level move and turn as one ``env.step`` of a
``MoreAgentEnv(sensors=False)``; this times a turn made directly (``motion.turn``) and through
``env.step``, and a collision-checked forward move, medians over batches of CPU time per step.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from collections.abc import Callable

from more_agent.sim import motion
from more_agent.sim.env import ACTION_TYPES, MoreAgentEnv
from more_agent.sim.scenes import get_scene
from more_agent.sim.world import World

BATCHES = 10


def _per_step_us(step: Callable[[], object], steps: int) -> float:
    """Median over batches of the CPU time of one call, in microseconds."""
    batch = max(1, steps // BATCHES)
    times = []
    for _ in range(BATCHES):
        t0 = time.process_time()
        for _ in range(batch):
            step()
        times.append((time.process_time() - t0) / batch * 1e6)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--scene", default="Rs_int")
    parser.add_argument("--steps", type=int, default=20_000)
    args = parser.parse_args()
    world = World.from_scene(get_scene(args.scene, 0))
    env = MoreAgentEnv(sensors=False, max_steps=None)
    env.reset(options={"world": world})
    turn_left = {"type": ACTION_TYPES.index("turn_left"), "target": "", "amount": 0.1}
    print(json.dumps({
        "scene": args.scene,
        "turn_direct_us": round(_per_step_us(lambda: motion.turn(world, 0.1), args.steps), 2),
        "turn_env_step_us": round(_per_step_us(lambda: env.step(turn_left), args.steps), 2),
        "move_forward_direct_us": round(_per_step_us(lambda: motion.move_forward(world, 0.0), args.steps // 10), 1),
    }))


if __name__ == "__main__":
    main()
