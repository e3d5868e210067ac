"""Command groups of the ``more-agent`` CLI, one module each."""
