"""Run time against error: ``python -m benchmarks [SUBJECT ...] [--quick] [--json] [--out DIR]``.

One module per subject (:data:`SUBJECTS`), each exposing the same small interface:

* ``TITLE`` -- the section's title in the report;
* ``run(section, quick)`` -- measure, writing into ``section`` (a :class:`verification.report.Section`) as it goes:
  ``section.csv(stem, rows)``, ``section.figure(fig, stem)``, ``section.add_text(heading, markdown, figures)``,
  ``section.summary[key] = value`` (the keys of ``summary.json`` and ``--json``) and ``section.target(label,
  measured, limit, unit)`` (a missed target makes the section, and the command, fail).

A new subject is one module and one entry of :data:`SUBJECTS`. Every timing is wall time on this machine, warm (a
first untimed call pays imports and caches), best of a few repeats; comparisons with another code or another way
are timed side by side, alternating, in one run, and reported as ratios.
"""

SUBJECTS = {
    "neck": "benchmarks.neck",  # fem_neck.neck_radius against a plain numpy Newton
    "fe": "benchmarks.fe",  # FE conductance: error against time, NGSolve, the periodic cells
    "fit": "benchmarks.fit",  # the main command python -m fem_neck fit: its sweep, its whole process beside NGSolve's
    "dem": "benchmarks.dem",  # DEM solvers: transient accuracy, steady scaling, linear solvers, OpenPNM
    "mechanics": "benchmarks.mechanics",  # the moving-particle loop against LAMMPS, compile cost, thermal-only path
    "electrical": "benchmarks.electrical",  # Zohdi 2014's Section 7 example, step cost, Kirchhoff against eq. 43
    "laws": "benchmarks.shared_body",  # the shared-body conductance law against today's, same packing, to 10^6
    "mpi": "benchmarks.distributed",  # the steady network on 1 and 2 MPI ranks (PETSc): strong and weak scaling
}
