"""The embedded BEHAVIOR-1K world: scenes, tasks, world state, magic actions, sensors, Gymnasium env."""
