"""Campaigns: many flights (procedure-database regression runs) on a process pool or a Dask cluster.
The seam for the regression issue; nothing here yet."""
