"""Option values that need the library (family names, centring modes, experiments, data sets):
computed when their command is parsed or its help shown (`hystkit.cli._common.deferred`), so
building the parser loads none of it. The imports here are inside the functions for that
reason: they are the parser's, not a command's."""

from __future__ import annotations

__all__ = ["compensation_value", "dataset_names", "default_centers", "experiment_names",
           "families", "family_info", "family_names", "pl_default_grid", "roles"]


def compensation_value(name: str):
    """A constant of `hystkit.compensation` (``CENTERS``, ``DEFAULT_CENTER``, ``MODES``...)."""
    from .. import compensation

    return getattr(compensation, name)


def families() -> dict:
    """The registered families by name (`hystkit.models.FAMILIES`: each loads when used)."""
    from ..models import FAMILIES

    return FAMILIES


def family_names() -> list[str]:
    return sorted(families())


def family_info() -> dict:
    """Names, titles and sizes of the families: no model loads for the help."""
    from ..models import FAMILY_INFO

    return FAMILY_INFO


def experiment_names() -> list[str]:
    from ..signals import EXPERIMENTS

    return sorted(EXPERIMENTS)


def default_centers() -> str:
    """Every deployable centring, comma-separated: ``select`` judges each the way it is used
    (a tare candidate on recordings that do not start at rest simply scores badly)."""
    return ",".join(compensation_value("DEPLOYABLE_CENTERS"))


def pl_default_grid(key: str) -> tuple:
    """The Power-Law structural search's default values of `key` (n, p, m, s)."""
    from ..models.pl import DEFAULT_GRID

    return DEFAULT_GRID[key]


def dataset_names() -> list[str]:
    from ..datasets import DATASETS

    return list(DATASETS)


def roles() -> tuple[str, ...]:
    from ..datasets import ROLES

    return ROLES
