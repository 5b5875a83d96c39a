"""Plain-text tables keep every value apart, however wide (issue 11: very negative R² values
ran together, e.g. '-1.1692-2390.9675')."""

from __future__ import annotations

from hystkit.studies import format_compare, format_table

ROW = {"n_params": 11, "fit_seconds": 1234.5, "r2_forward": -1.1692, "r2_compensated": -2390.9675,
       "r2_direct": -12345.6789, "linear_r2": 0.5, "r2_compensated_oracle": -2390.9675,
       "r2_direct_oracle": -1.1692, "linear_r2_oracle": -99999.0, "e_rms_pct": 123456.78,
       "rate_dependent": False, "return_point_memory": True, "minor_loops_close": None,
       "direct_status": "ok"}


def test_compare_table_separates_wide_values():
    row = format_compare({"mpl": ROW}).splitlines()[1]
    tokens = row.split()
    for value in ("-1.1692", "-2390.9675", "-12345.6789", "-99999.0000", "123456.78", "1234.50"):
        assert value in tokens, (value, row)


def test_compare_table_keeps_its_columns_for_ordinary_values():
    ordinary = dict(ROW, fit_seconds=0.25, r2_forward=0.99, r2_compensated=0.98,
                    r2_direct=0.97, linear_r2=0.9, r2_compensated_oracle=0.98,
                    r2_direct_oracle=0.97, linear_r2_oracle=0.9, e_rms_pct=1.5)
    head, row = format_compare({"mpl": ordinary}).splitlines()[:2]
    assert row.index("0.9900") == head.index("R² fwd")  # right-aligned under its header


def test_demo_table_separates_wide_values():
    metrics = {"sine": {"center": "fit", "r2": -2390.9675, "linear_r2": -1.1692,
                        "e_rms_pct": 12345.67, "loop_area": None, "r2_oracle": -123456.1234,
                        "linear_r2_oracle": -1.5}}
    row = format_table(metrics, "t").splitlines()[-1]
    assert row.split() == ["sine", "-2390.9675", "-1.1692", "12345.67", "-", "-123456.1234",
                           "-1.5000"]
