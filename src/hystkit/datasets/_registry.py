"""The registry of public data sets: list them, describe them, load a run by name."""

from __future__ import annotations

import os
from pathlib import Path
from types import MappingProxyType

from ..errors import InputError
from . import _bh_loops, _boucwen, _micromanipulator, _mr_damper, _piezo_actuator
from ._dataset import Dataset, DatasetInfo
from ._files import find_root

__all__ = ["DATASETS", "dataset_info", "list_datasets", "load", "shared_data_status"]

DATASETS = MappingProxyType({info.name: info for info in (
    _micromanipulator.INFO, _piezo_actuator.INFO, _mr_damper.INFO, _bh_loops.INFO,
    _boucwen.INFO)})


def list_datasets() -> tuple[DatasetInfo, ...]:
    """Every registered data set, in a fixed order; reads no file.

    Returns
    -------
    tuple of DatasetInfo
        The registry entries.
    """
    return tuple(DATASETS.values())


def dataset_info(name: str) -> DatasetInfo:
    """The registry entry of `name`; unknown names list the known ones (`InputError`).

    Parameters
    ----------
    name : str
        Registry name.

    Returns
    -------
    DatasetInfo
        Its registry entry.

    Raises
    ------
    InputError
        An unknown name.
    """
    try:
        return DATASETS[name]
    except KeyError:
        raise InputError(f"no dataset {name!r}; datasets: {', '.join(DATASETS)}") from None


def load(name: str, variant: str | None = None, *,
         root: str | os.PathLike[str] | None = None) -> Dataset:
    """Load one run of a registered data set from the shared data.

    Parameters
    ----------
    name : str
        See :func:`list_datasets` (``hystkit datasets list``).
    variant : str, optional
        The run; default the data set's ``default_variant``.
    root : path-like, optional
        Shared data root. Default: ``$HYSTKIT_SHARED_DATA``, else the first ``shared/data``
        found in the current directory, the hystkit source tree or a folder above them.

    Returns
    -------
    Dataset

    Raises
    ------
    InputError
        Unknown name or variant; shared data or the data set's folder or file absent (the
        message names the path expected); unreadable file.
    MissingDependencyError
        The variant's file format needs an optional package that is not installed.
    """
    return dataset_info(name).read(variant, root)


def shared_data_status(root: str | os.PathLike[str] | None = None) -> tuple[Path | None, str]:
    """Where the shared data root is and how it was found, or (None, why not).

    Parameters
    ----------
    root : str or os.PathLike, optional
        Use this folder instead of searching for the root.

    Returns
    -------
    path : pathlib.Path or None
        The shared data root, None if not found.
    how : str
        How it was found, or why not.
    """
    try:
        path, how = find_root(root)
    except InputError as exc:
        return None, str(exc)
    return path, how
