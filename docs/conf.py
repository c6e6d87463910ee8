"""Sphinx configuration of the sinterheat documentation.

Build (offline, warnings as errors, pages read and written on every core): ``python -m sphinx -W -j auto -b html docs
docs/_build`` after ``pip install '.[docs]'``.
The pages are Markdown (MyST), so ``tests/test_console_blocks.py`` runs their console blocks as it runs the README's;
the gallery is built by running every script of ``examples/`` (sphinx-gallery); the API reference is autodoc (napoleon)
over the packages in ``api_packages``, and ``_ext/api_check.py`` fails the build when one of their public functions or
classes is missing from it; an entry a gallery example uses shows that example (``_ext/gallery_links.py``). The site
reads offline: MathJax is served from the build's ``_static`` (sphinx-mathjax-offline, in the docs extra), and
``_ext/site_check.py`` fails the build when a page loads anything from another host or links to a page or anchor that
does not exist.

A build of the pages alone, without running the examples: ``python -m sphinx -D plot_gallery=0 -b html docs
docs/_build`` (the gallery's pages then show the code without its output or figures).
"""

import logging
import pathlib
import sys

DOCS = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))  # the local extensions (api_check, gallery_links, gallery_order, ...)
logging.getLogger("skfem").setLevel(logging.WARNING)  # its INFO lines (each assembly) would flood the build log

project = "sinterheat"
author = "the sinterheat authors"
copyright = "the sinterheat authors"

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "offline_maths",  # sphinx-mathjax-offline: MathJax 3 copied into _static/mathjax and loaded from there
    "nav_tree",  # furo's navigation tree from tables of contents cut to what it shows (half the pages' CPU time)
    "sphinx.ext.viewcode",
    "sphinx.ext.intersphinx",
    "sphinx_gallery.gen_gallery",
    "sphinx_copybutton",
    "api_check",
    "gallery_links",
    "scene_schema",
    "site_check",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
# sphinx-gallery's run-time tables (sg_execution_times.rst, read them as text) load jQuery from a CDN: not pages
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "gallery/*.ipynb", "gallery/*.py", "sg_execution_times.rst",
                    "gallery/sg_execution_times.rst"]

# MyST: $...$ and $$...$$ maths, heading anchors for [text](page.md#heading) links
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
myst_dmath_double_inline = True

# Every cross-reference must resolve (a broken one is a warning, so an error under -W). SciPy's names link to its
# site through the inventory committed in _intersphinx (read from the file: the build stays offline; it is the
# inventory of SciPy 1.10.1's documentation, as Debian's python-scipy-doc ships it). NumPy publishes no inventory that
# can be vendored here, so its names, and those of the other projects, are not linked.
intersphinx_mapping = {"scipy": ("https://docs.scipy.org/doc/scipy/", str(DOCS / "_intersphinx" / "scipy-objects.inv"))}
nitpicky = True
nitpick_ignore_regex = [
    (r"py:.*", r"(np|numpy|sp|scipy|skfem|meshio|pyvista|gmsh|argparse|pathlib|concurrent|typing|collections|io|"
               r"distributed|pyamg)\b.*"),
    (r"py:.*", r"(optional|callable|array|array_like|array-like|ndarray|sequence|iterable|mapping|path|object)"),
]

autodoc_default_options = {"undoc-members": True, "member-order": "bysource"}  # each automodule says :members:
autodoc_typehints = "description"
autodoc_typehints_format = "short"
autodoc_preserve_defaults = True
# viewcode: a source page's links to the reference use the module the object is documented in, not the first module
# that named it (following imports sent the classes of dem.engines.contact_heat to anchors under
# dem.engines.verlet.engine, which imports them)
viewcode_follow_imported_members = False
napoleon_google_docstring = False
napoleon_numpy_docstring = True

# The packages whose every public function and class must appear in the API reference (api_check).
api_packages = ["fem_neck", "dem", "sinterheat"]

sphinx_gallery_conf = {
    "examples_dirs": str(DOCS.parent / "examples"),
    "gallery_dirs": "gallery",
    "filename_pattern": r"\.py$",  # run every example (the default runs only plot_*.py)
    "within_subsection_order": "gallery_order.ExampleOrder",
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_signature": False,
    "only_warn_on_example_error": False,  # an example that raises fails the build
    "min_reported_time": 0,
    # which functions and classes of these packages each example uses: "Examples using this" under their API entries
    # (_ext/gallery_links.py)
    "doc_module": ("fem_neck", "dem", "sinterheat"),
    "backreferences_dir": "gen_modules/backreferences",
}

html_theme = "furo"
html_title = "sinterheat"
html_static_path = ["_static"]
html_css_files = ["maths.css"]  # display equations without a spurious scroll bar (the file says why)
html_favicon = "_static/favicon.svg"  # two sintered spheres
copybutton_prompt_text = "$ "
copybutton_only_copy_prompt_lines = False
