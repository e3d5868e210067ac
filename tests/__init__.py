"""Test suite of more-agent (a package so that spawned workers can import test helpers)."""
