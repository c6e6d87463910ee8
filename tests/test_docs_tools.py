"""The documentation's own machinery (``docs/_ext``), without building the site (CI builds it after the tests; one test
builds a one-page site of its own, where Sphinx is installed)."""

import pathlib
import re
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))

import api_check  # noqa: E402
import docstring_check  # noqa: E402
import gallery_links  # noqa: E402
import gallery_order  # noqa: E402
import site_check  # noqa: E402


def test_public_objects_are_the_functions_and_classes_each_module_defines():
    names = set(api_check.public_objects("fem_neck"))
    assert {"fem_neck.geometry.neck_radius", "fem_neck.conduction.Result", "fem_neck.cli.main"} <= names
    assert "fem_neck.geometry._validated" not in names  # private
    assert "fem_neck.neck_radius" not in names  # re-exported by the package: documented where it is defined
    assert "fem_neck.cluster.neck_geometry" not in names  # imported into the module, not defined there
    assert not any(".__main__" in name for name in names)  # importing it would run the command


def test_gallery_order_lists_the_fe_examples_first_and_puts_unlisted_ones_last():
    key = gallery_order.ExampleOrder(str(ROOT / "examples"))
    ordered = sorted(["transient_pair.py", "zzz_new.py", "aaa_new.py", "semisphere.py"], key=key)
    assert ordered == ["semisphere.py", "transient_pair.py", "aaa_new.py", "zzz_new.py"]
    assert set(gallery_order.ORDER) == {p.name for p in (ROOT / "examples").glob("*.py")}  # every example placed


def test_examples_fit_the_line_length():
    """Every line of every example within the project's 120 characters, and the code the gallery shows in its code
    column (all but the docstring and the text cells, ``# %%`` and the comment lines under it) within 79, so that
    none runs off the page."""
    import ast

    long = []
    for path in sorted((ROOT / "examples").glob("*.py")):
        lines = path.read_text().splitlines()
        docstring_end = ast.parse(path.read_text()).body[0].end_lineno
        text_cell = False
        for n, line in enumerate(lines, 1):
            text_cell = line.startswith("# %%") or (text_cell and line.startswith("#"))
            if len(line) > 120 or (n > docstring_end and not text_cell and len(line) > 79):
                long.append(f"{path.name}:{n}")
    assert long == []


# MyST directives whose body is not prose: read as a code block
NOT_PROSE = {"toctree", "eval-rst", "code-block", "code-cell", "literalinclude", "math", "scene-schema"}


def text_lines(text):
    """(number, line) of each line of a Markdown page's text: all but its code blocks (a fenced block, or a MyST
    directive whose body is not prose, ``NOT_PROSE``; CI runs the commands in them as they stand), its fence lines, its
    table rows (a row is one line) and a directive's ``:name: value`` option lines (MyST reads an option from one
    line). The body of any other directive (``{figure}``, ``{note}``) is text."""
    fences = []  # the open fences, innermost last: (fence, whether its body is text)
    options = False  # in a directive's option lines
    for n, line in enumerate(text.splitlines(), 1):
        stripped = line.lstrip()
        fence = re.match(r"(`{3,}|~{3,}|:{3,})(.*)", stripped)
        if fences and fence and fence[1][0] == fences[-1][0][0] and len(fence[1]) >= len(fences[-1][0]) \
                and not fence[2].strip():
            fences.pop()
            options = False
            continue
        if fences and not fences[-1][1]:
            continue  # code
        if fence:
            directive = re.match(r"\s*\{([\w:-]+)\}", fence[2])
            fences.append((fence[1], bool(directive) and directive[1] not in NOT_PROSE))
            options = fences[-1][1]
            continue
        options = options and stripped.startswith(":")
        if not options and not stripped.startswith("|"):
            yield n, line


def test_the_readme_fits_the_line_length():
    """Every line of the README's text (``text_lines``) within the project's 120 characters."""
    assert [n for n, line in text_lines((ROOT / "README.md").read_text()) if len(line) > 120] == []


def test_the_docs_pages_fit_the_line_length():
    """Every line of the text (``text_lines``) of every page under docs/ within the project's 120 characters."""
    long = []
    for path in sorted(p for p in (ROOT / "docs").rglob("*.md") if "_build" not in p.parts):
        long += [f"{path.relative_to(ROOT)}:{n}" for n, line in text_lines(path.read_text()) if len(line) > 120]
    assert long == [], "over 120 characters: " + ", ".join(long)


def test_text_lines_leave_out_code_tables_and_directive_options():
    """The line-length tests read what they should: a directive's prose but not its options, a code block (plain,
    indented in a list item, or a directive such as ``{toctree}``) not at all, a longer fence around a shorter one
    whole."""
    page = ("prose\n```python\ncode\n```\n- item\n\n  ```bash\n  indented code\n  ```\n| row |\n  | row in a list |\n"
            "```{figure} a.png\n:alt: option\n:width: option\n\ncaption\n```\n```{toctree}\nindex\n```\n"
            "````{note}\n```text\nnested code\n```\nnote's prose\n````\n:::{tip}\ntip's prose\n:::\nlast")
    assert [line for n, line in text_lines(page)] == [
        "prose", "- item", "", "", "caption", "note's prose", "tip's prose", "last"]


def test_getting_started_lists_every_example():
    page = (ROOT / "docs" / "getting-started.md").read_text()
    missing = {p.stem for p in (ROOT / "examples").glob("*.py") if f"<sphx_glr_gallery_{p.stem}.py>`" not in page}
    assert missing == set()


def test_every_module_with_public_objects_has_its_automodule():
    """What api_check finds in a build, found without one: every module of a documented package that defines a public
    function or class is named by an ``automodule`` directive of docs/reference/ (dem's modules included)."""
    text = "\n".join(p.read_text() for p in (ROOT / "docs" / "reference").rglob("*.rst"))
    placed = set(re.findall(r"^\.\. automodule:: (\S+)$", text, re.M))
    for package in ("fem_neck", "dem", "sinterheat"):
        modules = {name.rpartition(".")[0] for name in api_check.public_objects(package)}
        assert modules - placed == set(), package
    assert {"dem.scene.schema.display_rows", "dem.driver.run", "dem.laws.contact.jkr.JKRMaterial"} <= set(
        api_check.public_objects("dem"))


def test_gallery_links_match_an_api_entry_by_the_object_an_example_used():
    """An example's use of a function under its short public path (``fem_neck.neck_radius``) reaches the entry where
    the function is defined; a name no example uses, a constant and a name that is not there get no link."""
    from fem_neck.geometry import neck_radius
    from fem_neck.law import ConductanceLaw, pair_conductance

    used = [["neck_models.py", "examples", "gallery", "intro", "Neck models"]]
    found = gallery_links.index({"fem_neck.neck_radius": used, "fem_neck.geometry.neck_radius": used,
                                 "fem_neck.law.ConductanceLaw.default": used,
                                 "fem_neck.law.pair_conductance": [], "fem_neck.law.ROJEK": used,
                                 "fem_neck.law.no_such_law": used, "no_such_package.f": used})
    assert found == {id(neck_radius): ["fem_neck.neck_radius", "fem_neck.geometry.neck_radius"],
                     id(vars(ConductanceLaw)["default"].__func__): ["fem_neck.law.ConductanceLaw.default"]}
    assert id(pair_conductance) not in found
    assert gallery_links.lines(found[id(neck_radius)]) == [
        "", ".. rubric:: Examples using this", "",
        ".. minigallery:: fem_neck.geometry.neck_radius fem_neck.neck_radius", ""]


def test_site_check_finds_remote_loads_missing_files_and_missing_anchors(tmp_path):
    """A page that loads MathJax from a CDN, a stylesheet from another host and a missing local script, and links to
    an anchor its target lacks, is reported line by line; what a reader follows (an external link) and what is
    there is not."""
    (tmp_path / "_static").mkdir()
    (tmp_path / "_static" / "here.js").write_text("")
    (tmp_path / "guide").mkdir()
    (tmp_path / "guide" / "other.html").write_text('<h1 id="there">x</h1><a name="old">y</a>')
    (tmp_path / "index.html").write_text(
        '<script defer src="https://cdn.example.org/npm/mathjax@4/tex-mml-chtml.js"></script>'
        '<link rel="stylesheet" href="//fonts.example.org/a.css"><link rel="next" href="guide/other.html">'
        '<script src="_static/here.js"></script><script src="_static/gone.js"></script>'
        '<img src="data:image/png;base64,AAAA"><span id="self"></span>'
        '<a href="https://example.org/paper">paper</a><a href="mailto:a@b.c">mail</a><a href="#self">up</a>'
        '<a href="guide/other.html#there">ok</a><a href="guide/other.html#old">ok</a>'
        '<a href="guide/other.html#missing">bad</a><a href="#nowhere">bad</a><a href="gone.html">bad</a>')
    assert site_check.problems(tmp_path) == [
        "index.html: loads https://cdn.example.org/npm/mathjax@4/tex-mml-chtml.js from another host (the site must "
        "read offline)",
        "index.html: loads //fonts.example.org/a.css from another host (the site must read offline)",
        "index.html: loads _static/gone.js, which the build does not have",
        "index.html: links to guide/other.html#missing, but guide/other.html has no anchor 'missing'",
        "index.html: links to #nowhere, but index.html has no anchor 'nowhere'",
        "index.html: links to gone.html, which the build does not have",
    ]
    (tmp_path / "guide" / "back.html").write_text('<a href="../index.html#self">up</a><a href="../../x.html">out</a>')
    assert site_check.problems(tmp_path)[0] == "guide/back.html: ../../x.html points outside the site"  # page order


def test_a_build_with_a_cdn_script_fails(tmp_path):
    """site_check is wired into the build: a page that loads a script from another host fails ``sphinx -W`` (and the
    same page without it builds). Needs Sphinx (the docs extra); the tests' own environment may lack it."""
    sphinx_cmd = pytest.importorskip("sphinx.cmd.build")
    (tmp_path / "conf.py").write_text(f"import sys\nsys.path.insert(0, {str(ROOT / 'docs' / '_ext')!r})\n"
                                      "extensions = ['site_check']\n")
    page = "Title\n=====\n\n.. raw:: html\n\n   <script src=\"https://cdn.example.org/x.js\"></script>\n"
    (tmp_path / "index.rst").write_text(page)
    args = ["-W", "-q", "-b", "html", str(tmp_path), str(tmp_path / "_build")]
    assert sphinx_cmd.build_main(args) != 0
    (tmp_path / "index.rst").write_text(page.replace("https://cdn.example.org/x.js", "_static/x.js"))
    (tmp_path / "_static").mkdir()
    (tmp_path / "_static" / "x.js").write_text("")
    (tmp_path / "conf.py").write_text((tmp_path / "conf.py").read_text() + "html_static_path = ['_static']\n")
    assert sphinx_cmd.build_main(args + ["-E"]) == 0


def test_maths_is_served_by_the_site_itself():
    """conf.py draws the equations with a MathJax the build copies into ``_static`` (the docs extra installs it,
    ``_ext/offline_maths.py`` registers it), never one from a CDN: a page that still loaded a remote MathJax would
    also fail the build (site_check)."""
    import importlib.util
    import runpy
    import tomllib

    conf = runpy.run_path(str(ROOT / "docs" / "conf.py"))
    assert {"sphinx.ext.mathjax", "offline_maths", "site_check"} <= set(conf["extensions"])
    assert not site_check.is_remote(conf.get("mathjax_path", "")) and "mathjax3_config" not in conf
    extra = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]["docs"]
    assert any(req.startswith("sphinx-mathjax-offline") for req in extra)
    spec = importlib.util.find_spec("sphinx-mathjax-offline")
    if spec is not None:  # with the docs extra installed: the script it makes the pages load is in the package
        class App:  # what the extension's setup touches
            config = type("Config", (), {})()

            def connect(self, *args):
                pass

        app = App()
        assert importlib.import_module("offline_maths").setup(app) == {"parallel_read_safe": True,
                                                                      "parallel_write_safe": True}  # -j builds
        assert not site_check.is_remote(app.config.mathjax_path)
        assert (pathlib.Path(spec.origin).parent / "static" / "mathjax" / app.config.mathjax_path.split("/", 1)[1]
                ).is_file()


def test_offline_maths_lets_the_build_run_in_parallel(tmp_path):
    """``-j`` (the docs command's ``-j auto``) under ``-W`` fails with ``sphinx-mathjax-offline`` registered as it comes
    (its setup declares nothing, which Sphinx reads as unsafe in parallel, with a warning) and builds through
    ``offline_maths``, which MathJax's files still reach. Needs the docs extra."""
    sphinx_cmd = pytest.importorskip("sphinx.cmd.build")
    pytest.importorskip("sphinx-mathjax-offline")
    page = "Title\n=====\n\n:math:`a = \\sqrt{2 r h}`\n"
    (tmp_path / "index.rst").write_text(page)
    args = ["-W", "-q", "-j", "2", "-b", "html", str(tmp_path), str(tmp_path / "_build")]
    for extension, built in (("sphinx-mathjax-offline", False), ("offline_maths", True)):
        (tmp_path / "conf.py").write_text(f"import sys\nsys.path.insert(0, {str(ROOT / 'docs' / '_ext')!r})\n"
                                          f"extensions = ['sphinx.ext.mathjax', {extension!r}]\n")
        assert (sphinx_cmd.build_main(args + ["-E"]) == 0) == built, extension
    assert (tmp_path / "_build" / "_static" / "mathjax" / "tex-chtml.js").is_file()
    assert "_static/mathjax/tex-chtml.js" in (tmp_path / "_build" / "index.html").read_text()


def test_nav_tree_changes_no_page(tmp_path):
    """The navigation tree built from the cut tables of contents (``_ext/nav_tree.py``) gives every page byte for byte
    what the full ones give: a site with sections, API objects in the tables of contents, a toctree under a
    section, one inside ``only`` and a hidden one, built with furo both ways. Needs the docs extra."""
    sphinx_cmd = pytest.importorskip("sphinx.cmd.build")
    pytest.importorskip("furo")
    pages = {
        "index": "Site\n====\n\nIntro\n-----\n\n.. toctree::\n   :caption: Guide\n\n   a\n   b\n\n"
                 ".. only:: html\n\n   .. toctree::\n\n      d\n\n.. toctree::\n   :hidden:\n\n   e\n",
        "a": "A\n=\n\nOne\n---\n\nTwo\n---\n\n.. py:function:: f(x)\n\n.. py:class:: C\n\n   .. py:method:: m()\n",
        "b": "B\n=\n\nSection\n-------\n\n.. toctree::\n\n   c\n\nLater\n-----\n",
        "c": "C\n=\n\n.. py:function:: g()\n\nSub\n---\n\n.. py:function:: h()\n",
        "d": "D\n=\n\nx\n",
        "e": "E\n=\n\nSub E\n-----\n",
    }
    for name, text in pages.items():
        (tmp_path / f"{name}.rst").write_text(text)
    for extensions in ([], ["nav_tree"]):
        (tmp_path / "conf.py").write_text(f"import sys\nsys.path.insert(0, {str(ROOT / 'docs' / '_ext')!r})\n"
                                          f"html_theme = 'furo'\nextensions = {extensions!r}\n")
        out = tmp_path / f"_build{len(extensions)}"
        assert sphinx_cmd.build_main(["-W", "-q", "-E", "-b", "html", str(tmp_path), str(out)]) == 0
    built = sorted(path.relative_to(tmp_path / "_build0") for path in (tmp_path / "_build0").rglob("*.html"))
    assert len(built) == 8 and "c.html" in (tmp_path / "_build1" / "a.html").read_text()  # the nested page is there
    assert [str(page) for page in built
            if (tmp_path / "_build0" / page).read_bytes() != (tmp_path / "_build1" / page).read_bytes()] == []


def test_scipy_names_link_through_the_inventory_committed_with_the_docs():
    """intersphinx reads SciPy's inventory from the file under docs/ (no request at build time), and the inventory
    holds the names the docstrings use."""
    import posixpath
    import runpy

    uri, inventory = runpy.run_path(str(ROOT / "docs" / "conf.py"))["intersphinx_mapping"]["scipy"]
    assert uri.startswith("https://") and not site_check.is_remote(inventory)
    assert pathlib.Path(inventory).is_file() and pathlib.Path(inventory).is_relative_to(ROOT / "docs")
    loader = pytest.importorskip("sphinx.util.inventory").InventoryFile
    with open(inventory, "rb") as fh:
        names = loader.load(fh, uri, posixpath.join)["py:class"]
    assert names["scipy.sparse.csr_matrix"].uri == uri + "reference/generated/scipy.sparse.csr_matrix.html" \
        "#scipy.sparse.csr_matrix"


def test_install_page_shows_the_readme_mpi_command():
    """The install page's MPI block is the README's, which CI runs (so the page cannot drift from what works)."""
    def block_after(text):
        return text.split("<!-- mpi-command -->\n```bash\n", 1)[1].split("```", 1)[0]

    readme, page = (ROOT / "README.md").read_text(), (ROOT / "docs" / "install.md").read_text()
    assert block_after(page) == block_after(readme)


def test_citation_file_names_this_version_and_the_three_papers():
    import tomllib

    import yaml

    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0" and cff["authors"] and cff["type"] == "software"
    assert cff["version"] == tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    physics = " ".join((ROOT / "docs" / "physics" / "index.md").read_text().split())  # where the pages cite them
    assert [(ref["authors"][0]["family-names"], ref["year"]) for ref in cff["references"]] == [
        ("Rojek", 2022), ("Luding", 2005), ("Zohdi", 2014)]
    assert all(ref["title"] in physics for ref in cff["references"])


def test_described_reads_numpy_parameter_sections():
    doc = """Summary.

Parameters
----------
r_i, r_j : float
    The radii, m.
kappa : float
h
    Overlap, m.
*args
    More.

Returns
-------
K : float
    Conductance, W/K.
"""
    assert docstring_check.described(doc) == {"r_i", "r_j", "h", "args"}  # kappa has no description; K is returned
    assert docstring_check.described("Fields\n\nK: conductance.") == set()  # prose is not a Parameters section


# Every public parameter (of functions, classes and the public methods they define) is described in its docstring,
# numpy style ("Parameters" section: meaning and unit): a new public parameter comes with its description.


def test_every_public_parameter_is_described():
    missing = [name for package in ("fem_neck", "dem", "sinterheat") for name in docstring_check.undescribed(package)]
    assert missing == []


# Every public function, class, method and property has a docstring (its own, or the one of the method it overrides,
# which autodoc shows).
def test_every_public_object_has_a_docstring():
    missing = [name for package in ("fem_neck", "dem", "sinterheat") for name in docstring_check.undocumented(package)]
    assert missing == []



def test_formula_lines_find_ascii_formulas_and_pass_maths():
    """A docstring whose formulas are TeX (a role, one over two lines, a math block), with units, a power of ten, bold
    text, a parameter's name in a literal and a ``Parameters`` entry, has no ASCII formula; each sign of one is found
    on its own line: a function called, a power, a Greek letter spelled out, an equation with arithmetic; and a TeX
    backslash that Python read as an escape."""
    doc = r"""Summary with :math:`a = \sqrt{2 r h}` and a role over
two lines, :math:`K = \kappa \pi
r`, volumes in m^3 and kg/m^3, 10^6 particles, a/r = 3e-4, **Bold** text and ``kappa`` alone.

.. math::

    G(a) = \frac{Z}{3 a^2} = \phi(h_{ci}; r_i) - h

Parameters
----------
kappa : float
    Thermal conductivity, W/(m K).
"""
    assert docstring_check.formula_lines(doc) == []
    for ascii_formula in ("the ``ln(1/x)`` term", "an ``O(h^2)`` sliver", "grows as x**2", "conductivity kappa, W/(m K)",
                          "overlap ``h = r_i + r_j - d``", "a radius ``a = sqrt(2 r* h)``", "the lens at ``atan2(a, l)``",
                          "where ``K_i = c kappa_i pi a``"):
        assert docstring_check.formula_lines(doc + ascii_formula + "\n") == [ascii_formula], ascii_formula
    not_raw = "With :math:`\theta` in a docstring that is not raw."  # \t: Python reads a tab, MathJax gets "heta"
    assert docstring_check.formula_lines(not_raw) == [
        "a backslash read as an escape: write the docstring r\"\"\"...\"\"\""]


# Docstring formulas are TeX (``:math:`` roles, ``.. math::`` blocks), which MathJax draws on the site; the detector
# names every formula written in ASCII instead.
def test_docstring_formulas_are_maths():
    found = [line for package in ("fem_neck", "dem", "sinterheat") for line in docstring_check.ascii_formulas(package)]
    assert found == []


def test_no_tracked_file_carries_a_merge_conflict_marker():
    """A merge resolved by hand leaves no ``<<<<<<<``/``>>>>>>>`` lines behind (the contributing guide carried two
    such blocks for a while, rendered as text)."""
    import subprocess

    try:
        files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout")
    suffixes = {".py", ".md", ".rst", ".toml", ".txt", ".cfg", ".json", ".yml", ".yaml"}
    marked = []
    for name in files.decode().split("\0"):
        path = ROOT / name
        if not name or path.suffix not in suffixes or not path.is_file():
            continue
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            if line.startswith(("<<<<<<< ", ">>>>>>> ")):
                marked.append(f"{name}:{number}")
    assert not marked, marked
