"""Perception errors of a real robot (``--perception noisy``; the mode itself: :mod:`more_agent.perception_spec`).

``noise`` (the errors as array operations on frames and poses), ``taxonomy`` (which category an object
is confused with), ``model`` (one episode's errors, as the robot's embodiment applies them).
"""
