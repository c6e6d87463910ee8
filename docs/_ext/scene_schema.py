"""The scene schema page, made from the one schema table (:mod:`dem.scene.schema`): the directive ``scene-schema``
renders every table of a scene as a section of its own, with every key, the engines that read it (for a contact law's
material: the law), its type, default and unit, and its meaning -- the rows of
:func:`dem.scene.schema.display_rows`, so the page cannot drift from what the parser accepts.

Use it in a MyST page::

    ```{scene-schema}
    ```
"""

from __future__ import annotations

HEADER = ["| key | engines | type / default / unit | meaning |", "|---|---|---|---|"]


def cell(text: str) -> str:
    """``text`` in a cell of a Markdown table: its bars (``|E|``) escaped, which would otherwise end the cell."""
    return text.replace("|", "\\|")


def table_title(table: str) -> str:
    """How a scene writes the table: ``[solver]``, or ``[[walls]]`` for an array of tables."""
    from dem.scene import schema

    return f"[[{table}]]" if table in schema.ARRAYS else f"[{table}]"


def sections() -> list[tuple[str, str]]:
    """``(table, Markdown table of its keys)`` for every table of the schema, in the schema's order."""
    from dem.scene import schema

    rows: dict[str, list[str]] = {}
    for table, keys, engines, type_, meaning in schema.display_rows():
        rows.setdefault(table, list(HEADER)).append(f"| {keys} | {engines} | {cell(type_)} | {cell(meaning)} |")
    return [(table, "\n".join(lines) + "\n") for table, lines in rows.items()]


def setup(app):
    from docutils import nodes
    from docutils.statemachine import StringList
    from sphinx.util.docutils import SphinxDirective

    class SceneSchema(SphinxDirective):
        """One section per table of the scene schema, each with the table of its keys."""

        has_content = False

        def run(self):
            import importlib

            from dem.laws.contact import CONTACT_LAWS, law_module
            from dem.scene import schema

            modules = {schema}  # the page is read again when a table changes: the schema's, a law's material's or
            for name in CONTACT_LAWS:  # its sub-models' rows
                law = law_module(name)
                modules.update(module for module in law.modules.values() if module is not None)
                if law.composition.material is not None:
                    modules.add(importlib.import_module(law.composition.material))
            for module in sorted(modules, key=lambda m: m.__name__):
                self.env.note_dependency(module.__file__)
            out = []
            for table, text in sections():
                title = table_title(table)
                section = nodes.section(ids=[nodes.make_id(f"table-{table}")],
                                        names=[nodes.fully_normalize_name(title)])
                section += nodes.title(title, "", nodes.literal(title, title))
                self.state.nested_parse(StringList(text.splitlines(), source="dem.scene.schema"), self.content_offset,
                                        section)
                out.append(section)
            return out

    app.add_directive("scene-schema", SceneSchema)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
