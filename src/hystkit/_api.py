"""The notebook interface: ``import hystkit as hk``, then ``hk.read``, ``hk.fit``, ``hk.evaluate``.

Thin wrappers over the library (``hystkit.io``, ``hystkit.compensation``, ``hystkit.studies``)
that take a recording in whatever form a notebook holds it -- a `Recording`, a pandas
DataFrame with columns ``time`` [s], ``position`` [mm] and ``sensor``, or a file path -- and give
tables back as DataFrames. ``hystkit/__init__`` exports these names lazily (PEP 562), so
``import hystkit`` stays instant and the first call pays for the imports it needs.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ._api_reading import Data, as_recording, as_recordings, read, reading_options
from .compensation import (
    DEFAULT_CENTER,
    DEFAULT_LEVEL,
    Compensator,
    fit_compensator,
    interval,
    load_compensator,
    save_compensator,
    with_band,
)
from .compensation import evaluate as _evaluate
from .compensation import use_flags as _use_flags
from .io import remember_reading, training_units
from .models import get_family
from .studies import compare_models

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["compare", "compensate", "evaluate", "fit", "load", "read", "save"]


def fit(data: Data | Sequence[Data], model: str = "mpl", size: int | None = None, *,
        mode: str = "direct", center: str = DEFAULT_CENTER, band: bool = True,
        level: float = DEFAULT_LEVEL, **options: Any) -> Compensator:
    """Fit a compensator (sensor -> position) on one or several recordings.

    Parameters
    ----------
    data : Recording, DataFrame or path, or a sequence of them
        Fitting recording(s) with ``time`` [s], ``position`` [mm] and ``sensor``; several are
        fitted jointly, each with its own initial state and centring. A file whose settings
        file says ``gaps = "split"`` is fitted as its pieces between time gaps.
    model : str
        A model family of ``hystkit.models.FAMILIES`` (``mpl``, ``pi``, ``preisach``, ...).
    size : int, optional
        The family's size knob (mpl: cells N); default: the family's ``default_size``.
    mode : {"direct", "inverse"}
        ``direct`` fits sensor -> position; ``inverse`` fits position -> sensor and inverts it.
    center : {"fit", "tare", "track", "recording", "none"}
        How the sensor offset is removed in use (see ``docs/centring.md``); ``recording`` is the
        paper's oracle protocol, which a deployed compensator cannot have.
    band : bool, default True
        Calibrate a prediction band on the validation folds of the data (left-out recordings
        when there are several, interleaved cycles of one; the same model refitted on each
        fold, so the fit takes about four times as long); False: none.
    level : float, default 0.90
        The band's nominal coverage.
    **options
        Passed to `hystkit.compensation.fit_compensator` (``tare_seconds``, ``track_seconds``,
        ``diagnose``, the family's structure options such as ``slope_cap``).

    Returns
    -------
    Compensator
        ``fit_info["status"]`` is ``"ok"`` only when the fit converged, beats a straight line
        and has no parameter on a bound; ``estimate(recording)`` gives the position [mm],
        ``estimate_with_band(recording)`` the position with its band. Fitted on file paths
        read alike (one column mapping and time unit), its ``reading`` remembers how, as
        ``hystkit fit``'s model file does, so ``hystkit evaluate``, ``compensate``,
        ``report`` and ``stream --in`` read files of that layout without options; files read
        differently: None, and a note on stderr says so.

    Raises
    ------
    InputError
        A file that cannot be read, or recordings whose position or sensor units differ.

    Examples
    --------
    >>> import hystkit as hk
    >>> from hystkit.sensors import simulate_experiment
    >>> frame = simulate_experiment("noise", seed=1).to_frame()   # a DataFrame
    >>> comp = hk.fit(frame, "mpl", size=1)
    >>> comp.fit_info["status"], comp.fit_info["training_r2"] > comp.fit_info["training_linear_r2"]
    ('ok', True)
    """
    items = list(data) if isinstance(data, list | tuple) else [data]
    files = all(isinstance(item, str | os.PathLike) for item in items)
    reading = [reading_options(item) if isinstance(item, str | os.PathLike) else None
               for item in items]
    recordings = [rec for item, how in zip(items, reading) for rec in as_recordings(item, how)]
    units = training_units(recordings)  # recordings in different units are refused first
    comp = fit_compensator(recordings, size, model=model, mode=mode, center=center, **options)
    if band:
        options.pop("diagnose", None)
        comp = with_band(comp, recordings,
                         get_family(model).default_size if size is None else size, options,
                         level=level)
    # the model file remembers how its files were read, as ``hystkit fit``'s does
    comp, note = remember_reading(comp, units, reading if files else None, items)
    if note:
        print(f"hystkit: note: {note}", file=sys.stderr)
    return comp


def evaluate(compensator: Compensator, data: Data, *,
             rest_position: float | None = None, level: float | None = None) -> dict:
    """Score a compensator on a recording: deployable scores first, the oracle's labelled.

    Parameters
    ----------
    compensator : Compensator
        From :func:`fit` or :func:`load`.
    data : Recording, DataFrame or path
        A recording with ``position`` [mm].
    rest_position : float, optional
        ``tare`` centring: the position [mm] during the tare window (default: the training
        rest position).
    level : float, optional
        Nominal coverage of the band scored; default the band's own.

    Returns
    -------
    dict
        In this order: ``center`` and the deployable scores ``r2``, ``e_rms_pct``,
        ``e_max_pct``, ``sinad_db``, ``loop_area`` (the compensator's own, causal centring);
        the same with a ``linear_`` prefix (the straight-line baseline); ``center_oracle`` and
        every score again with an ``_oracle`` suffix (the paper's protocol: the recording's
        own means, not available in use); then ``n_samples``, ``extrapolated_fraction``,
        the use-time guard counts and their margins, and the band's ``band_coverage``,
        ``band_width_mean``, ``band_width_median`` and ``interval_score`` (None without a
        band). See `hystkit.compensation.evaluate`.

    Examples
    --------
    >>> import hystkit as hk
    >>> from hystkit.sensors import simulate_experiment
    >>> comp = hk.fit(simulate_experiment("noise", seed=1))
    >>> scores = hk.evaluate(comp, simulate_experiment("noise", seed=2))
    >>> list(scores)[:3]
    ['center', 'r2', 'e_rms_pct']
    >>> scores["r2"] > scores["linear_r2"]
    True
    >>> 0.8 < scores["band_coverage"] <= 1.0
    True
    """
    scores = _evaluate(compensator, as_recording(data), rest_position=rest_position,
                       level=level)
    return dict(sorted(scores.items(), key=lambda item: _score_rank(item[0])))


def _score_rank(key: str) -> int:
    if key == "center_oracle" or key.endswith("_oracle"):
        return 2
    if key == "center" or key.startswith(("r2", "e_", "sinad", "loop_area", "linear_")):
        return 1
    return 3


def compensate(compensator: Compensator, data: Data, *,
               rest_position: float | None = None, level: float | None = None) -> pd.DataFrame:
    """The recording as a DataFrame with the compensator's ``position_estimate`` [mm] added,
    and its band ``position_lower`` / ``position_upper`` [mm] when the compensator has one.

    Also adds the use-time guards ``sensor_outside`` and ``estimate_outside`` (True where the
    sensor or the estimate leaves the training range), as ``hystkit compensate`` writes them.

    Parameters
    ----------
    compensator : Compensator
    data : Recording, DataFrame or path
        The recording to compensate (``position`` is not needed).
    rest_position : float, optional
        ``tare`` centring: the position [mm] during the tare window.
    level : float, optional
        The band's nominal coverage; default the band's own (0.90 unless fitted otherwise).

    Returns
    -------
    pandas.DataFrame
        The recording's columns, ``position_estimate`` [mm], the band and the guard flags.

    Examples
    --------
    >>> import hystkit as hk
    >>> from hystkit.sensors import simulate_experiment
    >>> comp = hk.fit(simulate_experiment("noise", seed=1))
    >>> out = hk.compensate(comp, simulate_experiment("noise", seed=2))
    >>> out.columns.tolist()
    ['time', 'position', 'sensor', 'position_estimate', 'position_lower', 'position_upper', \
'sensor_outside', 'estimate_outside']
    """
    recording = as_recording(data)
    estimate = compensator.estimate(recording, rest_position=rest_position)
    frame = recording.to_frame()
    frame["position_estimate"] = estimate
    if compensator.band is not None:
        frame["position_lower"], frame["position_upper"] = interval(compensator, recording,
                                                                    estimate, level)
    for name, mask in _use_flags(compensator, recording, estimate).items():
        if mask is not None:
            frame[name] = mask
    return frame


def compare(fit_data: Data, val_data: Data, models: Sequence[str] | None = None, *,
            sizes: Mapping[str, int] | None = None) -> pd.DataFrame:
    """Fit several model families on one recording and score them on another.

    Parameters
    ----------
    fit_data, val_data : Recording, DataFrame or path
        Fitting and validation recordings (``time``, ``position``, ``sensor``).
    models : sequence of str, optional
        Family names; default: every registered family (minutes for all of them).
    sizes : mapping, optional
        Family name -> size; default: each family's ``default_size``.

    Returns
    -------
    pandas.DataFrame
        One row per model (the index), the columns of
        `hystkit.studies.compare_models`: ``n_params``, ``fit_seconds``, ``r2_forward``,
        ``r2_compensated``, ``r2_direct`` (deployable), ``linear_r2``, the ``_oracle`` scores,
        ``direct_status``, ...; a family whose fit failed has its reason in ``error``.

    Examples
    --------
    >>> import hystkit as hk
    >>> from hystkit.sensors import simulate_experiment
    >>> table = hk.compare(simulate_experiment("noise", seed=1),
    ...                    simulate_experiment("noise", seed=2), models=["mpl", "pi"])
    >>> table.index.tolist()
    ['mpl', 'pi']
    >>> bool((table["r2_direct"] > table["linear_r2"]).all())
    True
    """
    import pandas as pd  # here: fitting and scoring need no pandas (about 1 s to import)

    table = compare_models(as_recording(fit_data), as_recording(val_data), models, sizes)
    return pd.DataFrame.from_dict(table, orient="index")


def load(path: str | os.PathLike) -> Compensator:
    """Load a model file written by :func:`save` or ``hystkit fit --out`` (JSON or ``.mat``).

    Parameters
    ----------
    path : str or os.PathLike
        A ``.json`` or ``.mat`` model file.

    Returns
    -------
    Compensator
        The fitted compensator; ``source`` names `path`.

    Raises
    ------
    InputError
        A missing, damaged or foreign file (one line naming it).

    Examples
    --------
    >>> import hystkit as hk
    >>> from hystkit.sensors import simulate_experiment
    >>> comp = hk.fit(simulate_experiment("noise", seed=1))
    >>> _ = hk.save(comp, "model.json")
    >>> loaded = hk.load("model.json")
    >>> loaded.params == comp.params, loaded.center == comp.center
    (True, True)
    """
    return load_compensator(path)


def save(compensator: Compensator, path: str | os.PathLike, *, force: bool = False) -> Path:
    """Write a compensator to a model file; returns the path.

    Parameters
    ----------
    compensator : Compensator
        From :func:`fit` or :func:`load`.
    path : str or path-like
        ``.json`` (or ``.mat`` where `hystkit.compensation.save_compensator` supports it).
    force : bool
        Replace an existing file; without it an existing file is an error and is kept. The
        file appears whole or not at all.

    Returns
    -------
    pathlib.Path
    """
    return save_compensator(compensator, path, force=force)


