"""The embedded BEHAVIOR-1K world: scenes, tasks, world state, magic actions, sensors, Gymnasium env.

Importing this package registers the Gymnasium environment ``MoreAgent/Behavior-v0``
(``more_agent.sim.env.MoreAgentEnv``); the environment module itself loads on ``gymnasium.make``.
"""

import gymnasium as _gym

if "MoreAgent/Behavior-v0" not in _gym.registry:
    _gym.register(id="MoreAgent/Behavior-v0", entry_point="more_agent.sim.env:MoreAgentEnv")
