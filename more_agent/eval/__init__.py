"""Evaluation: episode records, the episode runner, metrics, resumable runs and reports."""
