"""Tests of more_agent.mapping."""
