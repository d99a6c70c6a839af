"""Campaigns: procedure-database regression runs (``fms-testbed regress``, ``docs/regression.md``).

Along the data path of a run:

* :mod:`.conditions` — the condition sets (wind, turbulence, navigation source);
* :mod:`.cases` — the cases (flyable sequence × aircraft × condition set), their stable ids and
  seeds, the seeded airport sample;
* :mod:`.worker` — one case flown in a worker process and turned into a row (:mod:`.rows`: the
  dataset's columns and Danilin's error classes);
* :mod:`.executors` — the local process pool and the dask.distributed cluster;
* :mod:`.store` — the campaign folder: ``run.json``, the ``flights/`` Parquet dataset written
  atomically per batch, resuming;
* :mod:`.runner` — a run from its options to its folder;
* :mod:`.diff`, :mod:`.report` (figures in :mod:`.figures`) — two runs compared, one run
  reported.
"""
