"""Tests of more_agent.eval."""
