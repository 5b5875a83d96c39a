"""``fit_compensator(loss=, f_scale=, weights=COLUMN)`` (issue 14.4): weights from a column of
the recordings, aligned with the samples fitted (several recordings end to end, direct and
inverse mode), honoured by the joint polish; AIC/BIC on the plain SSE."""

from __future__ import annotations

import numpy as np
import pytest

from hystkit.compensation import fit_compensator, weight_column
from hystkit.compensation._param_vector import flatten_params, simulate_segments
from hystkit.errors import InputError
from hystkit.io import Recording
from hystkit.sensors import simulate_experiment


@pytest.fixture(scope="module")
def recordings():
    return [simulate_experiment("sine", seed=1), simulate_experiment("decay", seed=2)]


def _renamed(rec: Recording, source: str, **columns) -> Recording:
    values = {"time": rec.time, "sensor": rec.sensor, "position": rec.position, **columns}
    return Recording(**values, source=source)


def _block_reversed(rec: Recording, column: str, block: slice) -> Recording:
    """`rec` with `column` reversed in time inside `block`: its mean and extremes (the
    centring and scaling) stay."""
    values = np.array(getattr(rec, column))
    values[block] = values[block][::-1]
    return _renamed(rec, rec.source, **{column: values})


# --- the weights column ---------------------------------------------------------------------

@pytest.mark.parametrize(("value", "why"), [(-0.5, "weight -0.5 is not a finite number >= 0"),
                                            (np.nan, "weight nan is not a finite number >= 0"),
                                            ("x1", "weight 'x1' is not a number"),
                                            (1e308, ("weight 1e+308 is above 1e+100 (only the "
                                                     "ratios of the weights matter: scale the "
                                                     "column down)"))])
def test_bad_weight_names_file_column_and_row(recordings, value, why):
    recs = [_renamed(r, f"rec{i}.csv") for i, r in enumerate(recordings)]
    w = np.ones(recs[1].n_samples, dtype=object if isinstance(value, str) else float)
    w[41] = value
    columns = [{"w": np.ones(recs[0].n_samples)}, {"w": w}]
    with pytest.raises(InputError) as err:
        weight_column(recs, "w", columns)
    assert str(err.value) == f"rec1.csv: column 'w', row 42: {why}"


def test_missing_and_zero_weights_are_refused(recordings):
    rec = _renamed(recordings[0], "a.csv")
    with pytest.raises(InputError, match=r"^a.csv: no weights column 'w' \(its other columns: "
                                         r"'temp'\)$"):
        weight_column([rec], "w", [{"temp": np.ones(rec.n_samples)}])
    with pytest.raises(InputError, match="every value of the weights column 'w' is 0"):
        weight_column([rec], "w", [{"w": np.zeros(rec.n_samples)}])


@pytest.mark.parametrize(("model", "size"), [("pi", None), ("mpl", 1)])
def test_weights_up_to_the_bound_are_scale_free(recordings, model, size):
    # the weighted SSE's minimiser depends only on the weights' ratios: the column times
    # 1e99 (below MAX_WEIGHT) gives the same compensator, its objective 1e99 times as large
    rec = recordings[0]
    w = np.ones(rec.n_samples)
    w[::7] = 3.0
    fits = [fit_compensator(rec, size, model=model, diagnose=False, weights="w",
                            other_columns=[{"w": w * scale}]) for scale in (1.0, 1e99)]
    # rtol: the two solves differ only in rounding (measured 1e-11 for pi, 1e-15 for mpl)
    np.testing.assert_allclose(flatten_params(fits[1].params)[0],
                               flatten_params(fits[0].params)[0], rtol=1e-9, atol=1e-12)
    assert fits[1].fit_info["objective"] == pytest.approx(1e99 * fits[0].fit_info["objective"],
                                                          rel=1e-9)


def test_text_weights_that_are_numbers_are_read(recordings):
    rec = recordings[0]
    text = np.array([f"{x:g}" for x in np.linspace(0, 2, rec.n_samples)], dtype=object)
    np.testing.assert_allclose(weight_column([rec], "w", [{"w": text}]),
                               [float(x) for x in text])


def test_a_robust_loss_is_refused_before_any_work_for_a_linear_model(recordings):
    with pytest.raises(InputError, match=r"model 'pi' fits the plain SSE only \(the losses its family "
                                         r"declares\); the cauchy loss is not available"):
        fit_compensator(recordings[0], model="pi", loss="cauchy")


# --- fits -----------------------------------------------------------------------------------

def test_unit_weights_give_the_unweighted_compensator(recordings):
    """The same minimum, compared where it is determined: the cost, and what the compensator
    estimates. The two take different searches (a weighted fit runs on scipy's trf, a plain
    1-cell mPL fit projects its weights out), which end at different points of a flat valley:
    the parameters differ by up to 2e-4 relative at costs 1.2e-9 apart (the plain one lower)."""
    rec = recordings[0]
    plain = fit_compensator(rec, 1, diagnose=False)
    ones = fit_compensator(rec, 1, diagnose=False, weights="w",
                           other_columns=[{"w": np.ones(rec.n_samples)}])
    np.testing.assert_allclose(ones.estimate(rec.sensor), plain.estimate(rec.sensor), rtol=0,
                               atol=1e-5 * np.ptp(rec.position))
    info = ones.fit_info
    assert info["cost"] == pytest.approx(plain.fit_info["cost"], rel=1e-8)
    assert (info["loss"], info["weights"]) == ("linear", "w")
    assert info["objective_label"] == "SSE weighted by column 'w'"
    n, k = info["training_samples"], info["n_params"]
    assert info["aic"] == pytest.approx(n * np.log(info["cost"] / n) + 2 * k, rel=1e-12)
    assert info["bic"] == pytest.approx(n * np.log(info["cost"] / n) + k * np.log(n),
                                        rel=1e-12)


@pytest.mark.parametrize(("mode", "target"), [("direct", "position"), ("inverse", "sensor")])
def test_zero_weights_make_targets_irrelevant_across_joined_recordings(recordings, mode,
                                                                       target):
    """Zero weights on a block of the second recording: reversing its targets there changes
    neither the family fit nor the joint polish, so the weights are aligned with the joined
    samples and honoured by both."""
    block = slice(2000, 2600)
    w1 = np.ones(recordings[1].n_samples)
    w1[block] = 0.0
    columns = [{"w": np.ones(recordings[0].n_samples)}, {"w": w1}]
    fits = []
    for second in (recordings[1], _block_reversed(recordings[1], target, block)):
        comp = fit_compensator([recordings[0], second], 1, mode=mode, diagnose=False,
                               weights="w", other_columns=columns)
        fits.append(comp)
    assert fits[0].fit_info["joint_fit"].startswith("joint polish over 2 recordings")
    np.testing.assert_allclose(flatten_params(fits[1].params)[0],
                               flatten_params(fits[0].params)[0], rtol=1e-6, atol=1e-8)
    assert fits[1].fit_info["objective"] == pytest.approx(fits[0].fit_info["objective"],
                                                          rel=1e-8)
    assert fits[1].fit_info["cost"] != pytest.approx(fits[0].fit_info["cost"], rel=1e-4)


def _rho_huber(z):
    return np.where(z <= 1, z, 2 * np.sqrt(z) - 1)


def test_joint_polish_minimises_the_robust_cost(recordings):
    """After the polish over two recordings (with spikes in the target), the huber objective
    over the per-recording runs is stationary (finite differences through the family's
    simulate), unlike at the SSE compensator's parameters."""
    rng = np.random.default_rng(0)
    position = np.array(recordings[1].position)
    spikes = rng.choice(position.size, position.size // 50, replace=False)
    position[spikes] = rng.uniform(position.min(), position.max(), spikes.size)
    recs = [recordings[0], _renamed(recordings[1], "spiky.csv", position=position)]
    f = 0.05
    robust = fit_compensator(recs, 1, diagnose=False, loss="huber", f_scale=f)
    plain = fit_compensator(recs, 1, diagnose=False)
    assert robust.fit_info["joint_fit"].startswith("joint polish over 2 recordings")
    assert robust.fit_info["objective_label"] == "huber cost (f_scale 0.05)"

    from hystkit.compensation import prepare_training_data

    _, s_list, p_list = prepare_training_data(recs, "fit")
    target = np.concatenate(p_list)
    family, structure = robust.family, robust.structure

    def cost(vector, rebuild):
        r = simulate_segments(family.simulate, structure, rebuild(vector), s_list) - target
        return float(f ** 2 * np.sum(_rho_huber(r ** 2 / f ** 2)))

    def gradient(params):
        vector, rebuild = flatten_params(params)
        steps = 1e-6 * np.maximum(1.0, np.abs(vector))
        return np.array([(cost(vector + e, rebuild) - cost(vector - e, rebuild)) / (2 * e[i])
                         for i, e in enumerate(np.diag(steps))])

    vector, rebuild = flatten_params(robust.params)
    assert robust.fit_info["objective"] == pytest.approx(cost(vector, rebuild), rel=1e-9)
    assert np.linalg.norm(gradient(robust.params)) < 1e-3 * np.linalg.norm(
        gradient(plain.params))
