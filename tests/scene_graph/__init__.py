"""Tests of more_agent.scene_graph."""
