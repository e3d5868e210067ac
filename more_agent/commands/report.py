"""``more-agent report DIR...``: merge runs into tables. (Owned by the evaluation work.)"""


def report() -> None:
    """Merge evaluation runs into one comparison table."""
    raise NotImplementedError
