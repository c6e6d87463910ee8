"""Luding, Manetsberger & Müllers 2005, Section 4, reproduced (the section ``sintering`` of ``python -m
verification``), one concern a module, each reading only those before it:

* :mod:`~verification.luding.protocol` -- the protocol of Sec. 4 as scenes (Table 1, the bi-axial box of Fig. 1, the
  schedule of Fig. 7);
* :mod:`~verification.luding.fragments` -- the fragments of a sample (clusters of contacts that hold);
* :mod:`~verification.luding.runs` -- the grid of runs, in parallel and resumed;
* :mod:`~verification.luding.study` -- the results of the runs read back;
* :mod:`~verification.luding.statements` -- every quantitative statement of Section 4 beside our number;
* :mod:`~verification.luding.causes` -- the runs that isolate the cause of each statement that does not hold;
* :mod:`~verification.luding.picture` -- a packing drawn;
* :mod:`~verification.luding.section` -- the section: figures, tables and the report, its prose the template
  ``prose.md``.
"""
