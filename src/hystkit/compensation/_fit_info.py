"""What a compensator's fit reported, as a frozen record: ``Compensator.fit_info``.

Read like a mapping (``info["status"]``, ``info.get("standard_errors")``, ``{**info}``); its
entries are what :func:`~hystkit.compensation.fit_compensator` measured (status, scores, cost,
standard errors, notes), or a model file's ``fit`` section as it was written (an older file's
keys included). A later step (the band's note, the training units) makes a new record with
:meth:`FitInfo.with_entries` instead of editing this one, and the model file writes
:meth:`FitInfo.to_dict`, the same keys in the same order as the dict it was made from.
"""

from __future__ import annotations

import copy
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

__all__ = ["FitInfo"]


@dataclass(frozen=True, eq=False, repr=False)
class FitInfo(Mapping[str, Any]):
    """A fit's report, read-only; equal to any mapping with the same entries.

    Parameters
    ----------
    entries : mapping of str to object, optional
        The report's entries (plain JSON values: numbers, strings, lists, dicts), copied.
    """

    entries: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        # its own read-only copy: editing the dict it was made from changes nothing here
        object.__setattr__(self, "entries", MappingProxyType(dict(self.entries)))

    def __getitem__(self, key: str) -> Any:
        return self.entries[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.entries)

    def __len__(self) -> int:
        return len(self.entries)

    def __repr__(self) -> str:
        return f"FitInfo({dict(self.entries)!r})"

    def __reduce__(self) -> tuple:
        # a mapping proxy does not pickle: workers send compensators back to the parent
        return (type(self), (dict(self.entries),))

    def with_entries(self, **entries: Any) -> FitInfo:
        """A new record: these entries added or replaced, the others kept in their order.

        Parameters
        ----------
        **entries
            The new entries, e.g. ``band="no band: ..."``.

        Returns
        -------
        FitInfo
        """
        return FitInfo({**self.entries, **entries})

    def to_dict(self) -> dict[str, Any]:
        """The entries as a plain dict (a deep copy), for the model file's ``fit`` section.

        Returns
        -------
        dict
        """
        return copy.deepcopy(dict(self.entries))
