"""``more-agent run TASK``: run one episode. (Owned by the episode work.)"""


def run(task: str) -> None:
    """Run one episode of TASK."""
    raise NotImplementedError
