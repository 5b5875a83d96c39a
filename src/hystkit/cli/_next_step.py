"""What to try after a refusal: the words after ``next: try`` (`say_next`), by its reason."""

from __future__ import annotations

from ..compensation import MAX_OUTSIDE, MIN_EXPLAINED

__all__ = ["next_step"]

_AUTO = ("--model auto (mpl with 1-3 cells, mpl-poly, pi and pl, each scored on held-out "
         "data)")
_EVALUATE_COLUMNS = ("checking that this file's columns are the training files' "
                     "(--columns position=NAME,sensor=NAME)")
_MORE_MODELS = {"select": "--models with more families (e.g. mpl,mpl-poly,pi,preisach)",
                "guided": "'hystkit select DATA --models mpl,mpl-poly,pi,preisach' (more "
                          "families than the guided list)"}
_TOO_LITTLE = ("the sensor may carry too little of the position: check the columns "
               "(--columns position=NAME,sensor=NAME)")
_COLUMNS = ("checking the columns: the sensor column may not carry the position "
            "(--columns position=NAME,sensor=NAME); no model recovers a signal that is not there")


def next_step(status: str, *, command: str = "fit", model: str | None = None,
              size: int | None = None, mode: str = "direct", line_r2: float | None = None,
              training_line_r2: float | None = None, outside: float | None = None) -> str:
    """What to try after a refusal whose reason is `status`, as the words after ``next: try``.

    Parameters
    ----------
    status : str
        A fit's status (``on_bounds``, ``not_converged``, ``collapsed``, ``no_signal``,
        ``poor``, ``worse_than_line``, ``no_limit``), a use verdict (``extrapolated``,
        ``poor``), or a selection's
        (``failed``: every candidate failed; ``refit``: the best ones' fits on all the data
        failed their guards; ``skipped``: candidates left out for the time budget).
    command : {"fit", "evaluate", "select", "guided"}
        The refusing command (``guided``: ``fit --model auto``): the same status asks for
        another step after a fit than after an evaluation or a selection.
    model, size, mode : optional
        The refused model's family, size and mode (``fit``); a selection's best candidate.
    line_r2 : float, optional
        R² of the straight line on the same data: a model below a line that explains nothing
        either (a noise-only sensor) is a sensor problem, not a model's.
    training_line_r2 : float, optional
        R² of the model's straight line on its training data (``evaluate``): where it explained
        nothing there either (an MR damper's force against its displacement), a line that
        explains nothing on the judged file says nothing about its columns.
    outside : float, optional
        Share of the judged sensor samples far outside the training range (``evaluate``): when
        it is above the verdict's limit, the data left the model's range, and a refit on data
        that cover it comes first, whatever the scores.
    """
    far_outside = command == "evaluate" and outside is not None and outside > MAX_OUTSIDE
    line_carried_signal = training_line_r2 is None or training_line_r2 >= MIN_EXPLAINED
    if (status == "worse_than_line" and line_r2 is not None and line_r2 < MIN_EXPLAINED
            and line_carried_signal):
        status = "no_signal"
    if far_outside and status == "no_signal":  # swapped columns, or data beyond the range
        return (f"{_EVALUATE_COLUMNS}; if they are, refitting on recordings that cover this "
                f"range ({outside:.0%} of its sensor samples lie far outside the training "
                f"range), e.g. 'hystkit fit TRAIN.csv THIS.csv' (fitted jointly)")
    if far_outside:
        status = "extrapolated"
    if command == "evaluate":
        return {
            "no_signal": f"{_EVALUATE_COLUMNS}: a sensor read from another column, or "
                         f"wired differently, carries nothing the model learnt",
            "extrapolated": "refitting on recordings that cover this range, e.g. 'hystkit fit "
                            "TRAIN.csv THIS.csv' (fitted jointly)",
            "poor": "refitting on recordings like these, e.g. 'hystkit fit TRAIN.csv THIS.csv' "
                    "(fitted jointly): what the model learnt holds only in part here (another "
                    "rate, amplitude or operating point than in training)",
        }.get(status, "refitting on recordings like these, e.g. 'hystkit fit TRAIN.csv "
                      "THIS.csv' (fitted jointly; without --model it chooses among small "
                      "models on held-out data)")
    if status == "no_signal":
        return _COLUMNS
    if command in ("select", "guided"):  # a selection (select, fit --model auto) refused
        centers = "--centers" if command == "select" else "--center"
        return {
            "worse_than_line": f"{centers} track (an offset that drifts) or one recording per "
                               f"run; if the straight line still wins, the sensor is linear "
                               f"enough for a straight-line calibration",
            "failed": "'hystkit fit DATA --model mpl --out m.json': one fit's own error says "
                      "what stops them",
            "skipped": "--budget with more seconds, or fewer samples (--resample HZ)",
            "poor": f"more recordings of the device (one per run) or {_MORE_MODELS[command]}; "
                    f"if no model explains more of the position held out, {_TOO_LITTLE}",
        }.get(status, f"'hystkit fit DATA --model {model or 'NAME'}"
                      f"{'' if size is None else f' --size {size}'}' (the best candidate): "
                      f"its refusal names what failed and what to try"
                      # the guided list is 6 direct-mode candidates; a B(H) loop of 129
                      # samples had none, and select's every family, both modes found an
                      # inverse Preisach at 0.98 held out
                      + ("; or 'hystkit select DATA --out m.json' (every family, both modes)"
                         if command == "guided" else ""))
    smaller = None if size is None or size <= 1 else size - 1
    if status == "on_bounds":
        if model == "mpl":
            fewer = f"--cells {smaller}" if smaller else "--cells 2"
            return (f"--model mpl-poly (a curved static curve in one cell) or {fewer}; "
                    f"{_AUTO} compares them")
        return (f"--size {smaller} (fewer parameters to pin) or {_AUTO}" if smaller
                else _AUTO)
    if status == "not_converged":
        return (f"--cells {smaller} (a smaller model settles within its evaluation budget) or "
                f"{_AUTO}" if smaller else f"another start (--init list) or {_AUTO}")
    if status == "collapsed":
        return ("--mode direct, or " + _AUTO if mode == "inverse"
                else f"{_AUTO}; if every model collapses, {_COLUMNS}")
    if status == "worse_than_line":
        return (f"{_AUTO}: {model or 'this model'} does no better than a straight line on "
                f"these data")
    if status == "poor":
        return (f"{_AUTO}: {model or 'this model'} explains too little of the position on its "
                f"own training data; if no model explains more, {_TOO_LITTLE}")
    if status == "no_limit":
        return "the fit without --no-limit (the stability limit keeps its Euler step bounded)"
    return _AUTO
