"""Scale-out: chunked work in process or on a Dask cluster (local or remote).

:func:`open_executor` gives the one executor every chunked command uses
(``reflectivity-map --scheduler``, ``sweep``); :func:`worker_cached` keeps what a task builds
(a Mitsuba scene) per worker process.
"""

from speclight.scale.executor import Executor, Outcome, error_text, open_executor
from speclight.scale.worker_cache import worker_cached

__all__ = ["Executor", "Outcome", "error_text", "open_executor", "worker_cached"]
