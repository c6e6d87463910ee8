"""numba's options for the contact laws' kernels, one definition for every sub-model.

``JIT`` compiles a kernel that is called on its own (from Python or another kernel); ``IN_LOOP`` one that the engines'
force loop (:mod:`dem.engines.contact_forces`) inlines, so that a law's kernels are part of its loop's code (faster
than calls there, slower to compile: the benchmarks guide, "Compile time of the force loop (a trial, left out)"). Both
cache the compiled code on disk and take numpy's semantics for division by zero and the like; fastmath stays off, so
that every operation is the IEEE one the tests compare closely.
"""

#: a kernel called on its own (from Python or from another kernel)
JIT = {"cache": True, "error_model": "numpy"}
#: a kernel the engines' force loop inlines
IN_LOOP = {**JIT, "inline": "always"}
