"""Independent pieces of work (family fits, train x test cells, CV folds, structures, sensors)
run in order-preserving maps, serially in-process or on Dask.

`open_executor` chooses: one worker (or a single piece) runs serially in this process and never
imports Dask; more run on Dask's multiprocessing scheduler with worker processes forked from
this one, one per core by default (where the platform cannot fork, a ``distributed`` local
cluster); a scheduler address connects to an existing cluster. Results come back in the order
of the pieces, whatever order they finish in, so a parallel run gives the same table as the
serial one; `fit_cost` estimates each piece so that the costliest start first. While a
parallel executor is open, `current_executor` gives it to work that splits itself: a long fit
screens its starts on the workers (:func:`hystkit.identification.fit_multistart`), and
`loading_meanwhile` has this process load what it needs after the map while it waits. Dask is
imported only when a parallel run starts.
"""

from ._contract import Executor, SerialExecutor, available_cores, current_executor
from ._cost import fit_cost
from ._executor import open_executor
from ._meanwhile import loading_meanwhile

__all__ = ["Executor", "SerialExecutor", "available_cores", "current_executor", "fit_cost",
           "loading_meanwhile", "open_executor"]
