"""The guided first fit's selection (`hystkit.studies.guided_select`, ``hystkit fit --model
auto``): its candidates, its time budget and the refusal when nothing fits within it. The
command's side (three lines, model file, refusals) is tests/cli/test_guided_fit.py."""

from __future__ import annotations

from hystkit.cli._next_step import next_step
from hystkit.compensation import Candidate, folds, protocol
from hystkit.io import read_recording
from hystkit.parallel import SerialExecutor, fit_cost
from hystkit.studies import guided_candidates, guided_select, selection_status
from hystkit.studies._guided import SHORT_LIST, SKIPPED, _Budgeted

from ..compensation.test_verdict_corpus import data  # noqa: F401 (the labelled corpus)


def test_the_candidates_are_the_short_list_cheapest_first(data):  # noqa: F811
    rec = read_recording(data["sine1"])
    cands = guided_candidates([rec])
    assert {(c.model, c.size) for c in cands} == set(SHORT_LIST)
    n = min(f.n_train for f in folds([rec]))
    costs = [fit_cost(c.model, c.size, n) for c in cands]
    assert costs == sorted(costs) and {c.mode for c in cands} == {"direct"}


def test_a_budget_too_small_for_any_candidate_says_so_and_what_to_try(data):  # noqa: F811
    rec = read_recording(data["sine1"])
    # 0.1 s for validation, serially: below every candidate's a-priori floor on 5333 samples
    result = guided_select([rec], budget=0.2, executor=SerialExecutor())
    assert result["winner"] is None and result["ranking"] == []
    assert [label for label, _ in result["skipped"]] == [c.label for c in
                                                          guided_candidates([rec])]
    assert result["protocol"] == protocol([rec])
    assert selection_status(result) == "skipped"
    assert next_step("skipped", command="guided").startswith("--budget with more seconds")


def test_pieces_after_the_deadline_are_skipped_not_run():
    def must_not_run(item):
        raise AssertionError(f"piece {item} ran after the deadline")

    cand = Candidate("mpl", 1, "direct", "fit")
    done = []
    budgeted = _Budgeted(SerialExecutor(), deadline=0.0)
    results = budgeted.map(must_not_run, [(cand, k, {}) for k in range(3)],
                           on_done=lambda i, r: done.append(i))
    assert results == [{"error": SKIPPED}] * 3 and done == [0, 1, 2]
    assert budgeted.late == {cand.label}
