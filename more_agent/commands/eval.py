"""``more-agent eval``: run many episodes, resumable. (Owned by the evaluation work.)"""


def eval_() -> None:
    """Evaluate a planner over a task set."""
    raise NotImplementedError
