"""``speclight reflectivity-map``: the target rendered into a reflectivity map.

* :mod:`.reflectivity_map_run`: the run (:func:`reflectivity_map`): checks, the store, the
  chunks as tasks of :mod:`speclight.scale` (in this process or on Dask);
* :mod:`.map_task` (one chunk, with what a worker keeps) and :mod:`.map_render` (its
  renders, through :mod:`speclight.render`);
* :mod:`.map_store`: the store as the writer sees it (create, resume, mark chunks);
* :mod:`.map_limits`: a chunk's memory and the store's size, checked first;
* :mod:`.cached_map`: a map of a scenario built into the cache folder and found there again
  (the light model of ``speclight shape --tumbling-starts`` without ``--map``).
"""

from speclight.maps.writer.reflectivity_map_run import MapRun, check_map_options, reflectivity_map

__all__ = ["MapRun", "check_map_options", "reflectivity_map"]
