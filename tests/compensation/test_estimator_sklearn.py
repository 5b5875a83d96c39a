"""CompensatorEstimator against scikit-learn's estimator contract (issue 11, part 4).

scikit-learn's own checks run through ``parametrize_with_checks``; the ones that do not apply
to a time series of one sensor column are listed in ``NOT_APPLICABLE`` with the reason. The
properties those checks would have tested (fit returns self, idempotent fit, input not
modified, pickling, read-only and Fortran-ordered input, lists for arrays) are then tested
here on a real time series.
"""

from __future__ import annotations

import pickle
import warnings

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

pytest.importorskip("sklearn")

from sklearn.base import clone
from sklearn.model_selection import GridSearchCV, TimeSeriesSplit
from sklearn.utils.estimator_checks import parametrize_with_checks

from hystkit.compensation import CompensatorEstimator, evaluate, fit_compensator
from hystkit.compensation._estimator import NotFittedError
from hystkit.io import Recording
from hystkit.sensors import simulate_experiment

_FEATURES = ("scikit-learn's generic data have 2 to 10 unrelated features; X here is one "
             "sensor column in time order (tested below on a time series)")
NOT_APPLICABLE = {
    name: _FEATURES for name in (
        "check_fit_score_takes_y", "check_estimators_overwrite_params",
        "check_dont_overwrite_parameters", "check_estimators_fit_returns_self",
        "check_readonly_memmap_input", "check_n_features_in_after_fitting",
        "check_positive_only_tag_during_fit", "check_estimators_dtypes", "check_dtype_object",
        "check_pipeline_consistency", "check_estimators_nan_inf", "check_estimators_pickle",
        "check_f_contiguous_array_estimator", "check_regressors_train",
        "check_regressor_data_not_an_array", "check_regressors_no_decision_function",
        "check_supervised_y_2d", "check_regressors_int", "check_methods_sample_order_invariance",
        "check_methods_subset_invariance", "check_fit2d_1sample", "check_dict_unchanged",
        "check_fit_idempotent", "check_fit_check_is_fitted", "check_n_features_in",
        "check_fit2d_predict1d")
}
NOT_APPLICABLE.update({
    "check_fit2d_1feature": "10 samples are too few for any model's parameters; the fit says "
                            "so (column 'position': 10 samples ...), not in scikit-learn's words",
    "check_estimators_unfitted": "raises hystkit's NotFittedError (a ValueError and an "
                                 "AttributeError, as scikit-learn's), not scikit-learn's own "
                                 "class: scikit-learn is not a dependency of hystkit",
})
DT = 0.025  # the virtual sensor's 40 Hz


with warnings.catch_warnings():  # not a BaseEstimator on purpose: scikit-learn is optional
    warnings.filterwarnings("ignore", "Estimator CompensatorEstimator does not inherit",
                            UserWarning)
    _SKLEARN_CHECKS = parametrize_with_checks([CompensatorEstimator(dt=DT)],
                                              expected_failed_checks=lambda e: NOT_APPLICABLE)


@_SKLEARN_CHECKS
def test_scikit_learn_checks(estimator, check):
    check(estimator)


@pytest.fixture(scope="module")
def series():
    fit_rec = simulate_experiment("noise", seed=1)
    val_rec = simulate_experiment("noise", seed=2)
    return fit_rec, val_rec


def _xy(rec: Recording) -> tuple[np.ndarray, np.ndarray]:
    return rec.sensor.reshape(-1, 1), rec.position


def test_init_stores_only_and_clone_copies_params():
    est = CompensatorEstimator("pi", size=4, center="tare", dt=DT, options={"diagnose": False})
    assert est.get_params() == {"model": "pi", "size": 4, "mode": "direct", "center": "tare",
                                "dt": DT, "options": {"diagnose": False}, "band": True,
                                "level": 0.9}
    copy = clone(est)
    assert copy is not est and copy.get_params() == est.get_params()
    assert copy.set_params(size=7) is copy and copy.size == 7 and est.size == 4
    with pytest.raises(ValueError, match="invalid parameter 'n_cells'"):
        est.set_params(n_cells=3)
    assert repr(est).startswith("CompensatorEstimator(model='pi', size=4")


def test_score_is_the_deployable_r2_of_evaluate(series):
    """Independent path: fit_compensator + evaluate on Recordings give the same numbers."""
    fit_rec, val_rec = series
    est = CompensatorEstimator("mpl", size=1, dt=fit_rec.dt)
    with pytest.raises(NotFittedError, match="not fitted"):
        est.predict(_xy(val_rec)[0])
    assert est.fit(*_xy(fit_rec)) is est
    comp = fit_compensator(fit_rec, 1)
    assert est.compensator_.params == comp.params
    assert_allclose(est.predict(_xy(val_rec)[0]), comp.estimate(val_rec), rtol=0, atol=1e-12)
    assert est.score(*_xy(val_rec)) == pytest.approx(evaluate(comp, val_rec)["r2"], abs=1e-12)
    assert est.n_features_in_ == 1 and est.dt_ == pytest.approx(fit_rec.dt)


def test_time_series_versions_of_the_skipped_checks(series):
    fit_rec, val_rec = series
    X, y = _xy(fit_rec)
    X_val = _xy(val_rec)[0]
    X_before, y_before = X.copy(), y.copy()
    est = CompensatorEstimator("mpl", dt=fit_rec.dt).fit(X, y)
    first = est.predict(X_val)
    assert_array_equal(X, X_before)  # input not modified
    assert_array_equal(y, y_before)
    params = dict(est.get_params())
    est.fit(X, y)  # idempotent, parameters untouched
    assert est.get_params() == params
    assert_array_equal(est.predict(X_val), first)
    again = pickle.loads(pickle.dumps(est))
    assert_array_equal(again.predict(X_val), first)
    fortran, readonly = np.asfortranarray(X_val), X_val.copy()
    readonly.setflags(write=False)
    assert_array_equal(est.predict(fortran), first)
    assert_array_equal(est.predict(readonly), first)
    assert_array_equal(est.predict(X_val.tolist()), first)  # a list for an array
    # the rows are a time series: the model has memory, so reversed time gives another answer
    assert not np.array_equal(est.predict(X_val[::-1])[::-1], first)


def test_fit_with_time_takes_dt_from_it(series):
    fit_rec, _ = series
    X, y = _xy(fit_rec)
    by_time = CompensatorEstimator().fit(X, y, time=fit_rec.time)
    by_dt = CompensatorEstimator(dt=fit_rec.dt).fit(X, y)
    assert by_time.compensator_.params == by_dt.compensator_.params
    with pytest.raises(ValueError, match="needs dt"):
        CompensatorEstimator().fit(X, y)
    with pytest.raises(ValueError, match="but dt is"):
        CompensatorEstimator(dt=2 * fit_rec.dt).fit(X, y, time=fit_rec.time)


def test_bad_input_is_refused_in_one_line(series):
    fit_rec, _ = series
    X, y = _xy(fit_rec)
    est = CompensatorEstimator(dt=DT)
    with pytest.raises(ValueError, match="expecting 1 feature"):
        est.fit(np.hstack([X, X]), y)
    with pytest.raises(ValueError, match="Expected 2D array"):
        est.fit(X[:, 0], y)
    bad = X.copy()
    bad[5, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        est.fit(bad, y)
    with pytest.raises(ValueError, match="one position per row"):
        est.fit(X, y[:-1])
    with pytest.raises(ValueError, match="sample_weight"):
        est.fit(X, y).score(X, y, sample_weight=np.ones(y.size))


@pytest.mark.parametrize("model", ["mpl", "pi"])
def test_grid_search_over_size_with_time_series_split(series, model):
    """GridSearchCV picks the size with the best mean deployable R² over the folds; checked
    against the same folds scored by hand."""
    fit_rec, _ = series
    X, y = _xy(fit_rec)
    sizes = [1, 2, 3] if model == "mpl" else [2, 4, 6]
    cv = TimeSeriesSplit(n_splits=2)
    search = GridSearchCV(CompensatorEstimator(model, dt=fit_rec.dt), {"size": sizes},
                          cv=cv).fit(X, y)
    by_hand = []
    for size in sizes:
        folds = [CompensatorEstimator(model, size, dt=fit_rec.dt).fit(X[tr], y[tr])
                 .score(X[te], y[te]) for tr, te in cv.split(X)]
        by_hand.append(np.mean(folds))
    assert_allclose(search.cv_results_["mean_test_score"], by_hand, rtol=0, atol=1e-9)
    assert search.best_params_["size"] == sizes[int(np.argmax(by_hand))]
    assert search.best_estimator_.compensator_.model == model
