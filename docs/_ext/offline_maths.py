"""MathJax served from the built site (the ``sphinx-mathjax-offline`` package), declared safe for a parallel build.

The package's ``setup`` returns no metadata, which Sphinx reads as "not safe for parallel reading": it then warns
(an error under ``-W``) and builds on one process. What the package does is safe in parallel: it sets
``mathjax_path`` and copies MathJax into ``_static`` when the build has finished, in the main process.
"""

import importlib


def setup(app):
    """Register ``sphinx-mathjax-offline`` and declare it parallel-safe.

    Parameters
    ----------
    app : sphinx.application.Sphinx
        The application being set up.

    Returns
    -------
    dict
        The extension's metadata: safe for parallel reading and writing.
    """
    importlib.import_module("sphinx-mathjax-offline").setup(app)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
