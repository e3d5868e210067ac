"""The public functions of ``more_agent.mapping`` document themselves as scikit-image does (numpydoc
with a ``>>>`` example), and the suite runs those examples (``--doctest-modules``, pyproject.toml)."""

import inspect

import pytest

import more_agent.mapping as mapping


def test_public_functions_have_numpydoc_examples() -> None:
    functions = {name: getattr(mapping, name) for name in mapping.__all__ if inspect.isfunction(getattr(mapping, name))}
    assert len(functions) >= 10
    missing = [name for name, f in functions.items()
               if not all(part in (inspect.getdoc(f) or "") for part in ("Parameters\n", "Returns\n", "Examples\n", ">>> "))]
    assert not missing, f"no numpydoc Parameters / Returns / Examples: {missing}"


def test_the_suite_runs_the_examples(request: pytest.FixtureRequest) -> None:
    assert request.config.getoption("doctestmodules")
    paths = [str(p) for p in request.config.getini("testpaths")]
    assert "more_agent/mapping" in paths and "more_agent/sim/grid.py" in paths
