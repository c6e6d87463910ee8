"""The site's navigation tree (furo's left sidebar) built without copying every page's whole table of contents.

furo draws on every page the whole toctree of the site, titles only (``toctree(titles_only=True, maxdepth=-1,
...)``). Sphinx builds it by copying each document's table of contents in full, with an entry for every function and
class of the API reference (``toc_object_entries``), and only then drops all but each document's title and the
toctrees below it: for the 180 pages of this site those copies were 45 % of the build's time without the examples.
While the page asks for a titles-only tree, this extension hands Sphinx the tables of contents already cut to what
that tree keeps (each top entry's title, and the branches that hold a toctree), so the pages come out the same
(``tests/test_docs_tools.py`` builds a site both ways and compares every page). A page's own contents ("on this
page") are not touched.
"""

from __future__ import annotations


def _cut(node, top: bool):
    """A copy of the table-of-contents ``node`` cut to what a titles-only toctree keeps, or None if nothing is kept.

    Parameters
    ----------
    node : docutils.nodes.Node
        A node of a document's table of contents (``env.tocs``).
    top : bool
        Whether ``node`` is at the top of the table (its list items are the document's titles, kept whole).

    Returns
    -------
    docutils.nodes.Element or None
        The cut copy: top list items keep their title paragraph; below them only the branches that hold a toctree
        node (``only`` nodes kept on the way, for Sphinx to filter by tags as before).
    """
    from docutils import nodes
    from sphinx import addnodes

    if isinstance(node, addnodes.toctree):
        return node.deepcopy()
    if not isinstance(node, nodes.Element):
        return None
    if top and isinstance(node, nodes.list_item) and len(node):
        copy = node.copy()
        copy += node[0].deepcopy()  # the title
        copy.extend(kept for kept in (_cut(child, False) for child in node[1:]) if kept is not None)
        return copy
    kept = [k for k in (_cut(child, top and isinstance(node, (nodes.bullet_list, addnodes.only)))
                        for child in node.children) if k is not None]
    if not kept and not top:
        return None
    copy = node.copy()
    copy.extend(kept)
    return copy


def _titles_only_tocs(builder) -> dict:
    """Every document's table of contents cut by :func:`_cut`, made once per build and process (a parallel
    writer's too), kept on the builder (the environment is pickled, the builder is not)."""
    cut = getattr(builder, "_nav_tree_tocs", None)
    if cut is None:
        cut = {docname: _cut(toc, True) for docname, toc in builder.env.tocs.items()}
        builder._nav_tree_tocs = cut
    return cut


def wrap_toctree(app, pagename, templatename, context, doctree):
    """Replace the page context's ``toctree`` by one that builds titles-only trees from the cut tables of contents.

    Parameters
    ----------
    app : sphinx.application.Sphinx
        The application.
    pagename, templatename : str
        The page and its template (unused).
    context : dict
        The page's template context; its ``toctree`` is wrapped.
    doctree : docutils.nodes.document or None
        The page's doctree (unused).
    """
    toctree = context.get("toctree")
    if toctree is None:
        return
    env = app.builder.env

    def titles_only_from_cut_tocs(**kwargs):
        if not kwargs.get("titles_only"):
            return toctree(**kwargs)
        full = env.tocs
        env.tocs = _titles_only_tocs(app.builder)
        try:
            return toctree(**kwargs)
        finally:
            env.tocs = full

    context["toctree"] = titles_only_from_cut_tocs


def setup(app):
    """Connect :func:`wrap_toctree` before the theme computes its navigation tree.

    Parameters
    ----------
    app : sphinx.application.Sphinx
        The application being set up.

    Returns
    -------
    dict
        The extension's metadata: safe for parallel reading and writing.
    """
    app.connect("html-page-context", wrap_toctree, priority=400)  # furo's handler has the default 500
    return {"parallel_read_safe": True, "parallel_write_safe": True}
