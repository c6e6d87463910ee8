"""Plumbing shared by the packages' command lines (``python -m fem_neck``, ``python -m dem``, ``python -m
verification``, ``python -m benchmarks``): argument parsing and result printing (:mod:`sinterheat.cli`; help texts from
docstrings, :mod:`sinterheat.help_text`), Ctrl-C handling (:mod:`sinterheat.interrupt`), numba's on-disk cache of
both packages' compiled kernels (:mod:`sinterheat.jit_cache`) and the pool that runs a sweep's independent jobs on
local processes or a Dask cluster (:mod:`sinterheat.pool`). It imports none of the packages, so each of them can use it
without pulling in another's code."""
