"""numba's options for the contact laws' kernels, one definition for every sub-model.

``JIT`` compiles a kernel that is called on its own (from Python or another kernel); ``IN_LOOP`` one that the engines'
force loop (:mod:`dem.engines.contact_forces`) inlines, so that a law's kernels are part of its loop's code (10 %
faster than calls there). Both cache the compiled code on disk and take numpy's semantics for division by zero and
the like; fastmath stays off, so that every operation is the IEEE one the tests compare closely.
"""

JIT = {"cache": True, "error_model": "numpy"}
IN_LOOP = {**JIT, "inline": "always"}
