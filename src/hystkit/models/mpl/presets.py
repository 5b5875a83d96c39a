"""The reference document's published one-cell mPL parameter sets (table 5.2, paper 9.1).

All are for data normalised to max |.| = 1 (eq. 5.10), the units hystkit's fits work in; the
document divides by max |.| without centring, so its ``V_b`` also carries the data's offset
(hystkit centres first, docs/fitting_setups.md). The document states no sample time for its
fit; the values are used at the recording's ``dt``. The fitted column is the *unlimited* sinh
model's (sec. 5.3.3 has no eq. 5.29 yet): its cell resistor ``2 I_S sinh(v / V_T)`` with
``V_T = 0.0307`` reaches the Euler slope ``f' dt = 2`` at ``|v| = 0.51`` at 40 Hz.
"""

from __future__ import annotations

from . import model as mpl

__all__ = ["PRESETS", "preset"]

#: name -> (printed values, source). Keys as the document prints them: I_S, V_T, w, V_b.
PRESETS: dict[str, tuple[dict, str]] = {
    "table-5.2": (
        {"i_s": 0.1, "v_t": 0.2, "w": [1.0, 0.4], "v_b": -0.6},
        ("reference document table 5.2, initial conditions (sec. 5.3.3), N = 1, normalised "
        "data (eq. 5.10)")),
    "table-5.2-fitted": (
        {"i_s": 1.72e-7, "v_t": 0.0307, "w": [0.1972, 0.1975], "v_b": -0.6775},
        ("reference document table 5.2, fitted weights (fmincon, sum of weights <= 100, "
        "unlimited sinh), N = 1, normalised data (eq. 5.10)")),
    "paper-9.1": (
        {"i_s": 0.1, "v_t": 0.2, "w": [1.0, 0.4], "v_b": -0.6},
        ("paper 9.1, initial conditions (I_S = 0.1, V_T = 0.2, w0 = 1, w1 = 0.4, V_b = -0.6), "
        "N = 1, normalised data")),
}


def preset(name: str, dt: float = 0.025,
           limit: bool = True) -> tuple[mpl.MplStructure, mpl.MplParams, dict]:
    """One published parameter set as ``(structure, params, info)``.

    Parameters
    ----------
    name : str
        A key of :data:`PRESETS`.
    dt : float, default 0.025
        Sample time of the structure [s] (the document gives none; 40 Hz is the lab's rate).
    limit : bool, default True
        Whether the structure applies the stability limit (eq. 5.29); the document's own model
        had none (``limit=False``).

    Returns
    -------
    structure : MplStructure
        One cell at ``dt``.
    params : MplParams
        The printed values.
    info : dict
        ``source`` (table or paper) and ``units`` (normalised, eq. 5.10).

    Raises
    ------
    KeyError
        If there is no such preset.
    """
    values, source = PRESETS[name]
    params = mpl.MplParams(i_s=[values["i_s"]], v_t=[values["v_t"]], w=values["w"],
                           v_b=values["v_b"])
    return (mpl.MplStructure(n_cells=1, dt=dt, limit=limit), params,
            {"source": source, "units": "normalised data, max |.| = 1 (eq. 5.10)"})
