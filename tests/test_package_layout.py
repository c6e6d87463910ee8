"""The tree's rules, read from the source (no import is executed): the directions imports may take between the
folders of ``dem``, no import cycle (also through an import inside a function), what ``dem`` may take from ``fem_neck``
(and ``fem_neck`` from nothing of ours but the shared plumbing), no name that is defined but used nowhere, and no
function of ``dem`` that takes more than ``MAX_PARAMETERS`` (the compiled loops take records:
:mod:`dem.engines.records`)."""

import ast
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
PACKAGES = ("dem", "fem_neck", "sinterheat", "verification", "benchmarks")

# The folders (and top-level modules) of dem, lowest first: each may import only from those before it (and from
# itself). The memory estimate and the MPI plumbing (parallel: communicator, reductions, halo exchange, PETSc) know
# nothing of the rest, geometry and output only of them; the laws use geometry; the networks both; a scene is parsed
# into all of these; the engines run scenes; the driver runs engines; the command line and the package's front door
# come last. (The compiled-code cache is the shared plumbing's: sinterheat.jit_cache.)
DEM_LAYERS = (("memory", "parallel"), ("geometry", "output"), ("laws",), ("network",), ("scene",), ("engines",),
              ("driver",), ("cli", "__main__", "__init__"))
FEM_NECK_FOR_DEM = ("fem_neck.geometry", "fem_neck.law")
MAX_PARAMETERS = 16


def modules():
    """``{dotted name: path}`` of every module of the packages."""
    out = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            if "__pycache__" in path.parts:  # the compiled-code cache's copies of contact-law loops
                continue
            parts = path.relative_to(ROOT).with_suffix("").parts
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            out[name] = path
    return out


def imports(path: pathlib.Path, name: str):
    """The modules ``path`` (module ``name``) imports anywhere in it (at module level, inside functions and classes):
    ``(imported name, line)``, relative imports resolved."""
    tree = ast.parse(path.read_text())
    nodes = ast.walk(tree)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    for node in nodes:
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, node.lineno
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[:len(anchor) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            yield base, node.lineno
            for alias in node.names:  # from package import module
                yield f"{base}.{alias.name}", node.lineno


def resolved(imported: str, known) -> str | None:
    """The longest module of ours that ``imported`` names (a ``from m import f`` also yields ``m.f``)."""
    while imported:
        if imported in known:
            return imported
        imported = imported.rpartition(".")[0]
    return None


def layer(name: str) -> int:
    """The rank of the dem module ``name`` in :data:`DEM_LAYERS`."""
    unit = name.split(".")[1] if name.count(".") else "__init__"
    for rank, units in enumerate(DEM_LAYERS):
        if unit in units:
            return rank
    raise AssertionError(f"{name}: its folder is in no layer of DEM_LAYERS")


@pytest.mark.slow
def test_dem_imports_only_downward():
    known = modules()
    wrong, checked = [], 0
    for name, path in known.items():
        if not name.startswith("dem"):
            continue
        for imported, line in imports(path, name):
            target = resolved(imported, known)
            if target is None or not target.startswith("dem.") or target == name:
                continue
            checked += 1
            if layer(target) > layer(name) or (layer(target) == layer(name)
                                               and target.split(".")[1] != name.split(".")[1]):
                wrong.append(f"{path.relative_to(ROOT)}:{line} imports {target}")
    assert checked > 100 and not wrong, "imports against DEM_LAYERS:\n" + "\n".join(wrong)


@pytest.mark.slow
def test_no_import_cycle():
    """No module imports, at module level or inside a function, a module that imports it back (directly or through
    others): an import inside a function hides a cycle from Python until the function runs, not from this test."""
    known = modules()
    graph = {name: set() for name in known}
    for name, path in known.items():
        for imported, _ in imports(path, name):
            target = resolved(imported, known)
            if target is not None and target != name and not name.startswith(target + "."):
                graph[name].add(target)
    assert "dem.driver" in graph["dem"]  # the graph was read
    state, cycles = {}, []

    def visit(node, trail):
        state[node] = "open"
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                cycles.append(" -> ".join(trail[trail.index(nxt):] + [nxt]) if nxt in trail else f"{node} -> {nxt}")
            elif nxt not in state:
                visit(nxt, trail + [nxt])
        state[node] = "done"

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])
    assert not cycles, "import cycles:\n" + "\n".join(cycles)


@pytest.mark.slow
def test_dem_takes_only_the_geometry_and_the_law_from_fem_neck_and_fem_neck_nothing_from_the_others():
    known = modules()
    wrong = []
    for name, path in known.items():
        for imported, line in imports(path, name):
            target = resolved(imported, known)
            if target is None or target == "fem_neck":
                continue
            where = f"{path.relative_to(ROOT)}:{line} imports {target}"
            if name.startswith("dem") and target.startswith("fem_neck") and not target.startswith(FEM_NECK_FOR_DEM):
                wrong.append(where)
            if name.startswith("fem_neck") and target.split(".")[0] in ("dem", "verification", "benchmarks"):
                wrong.append(where)
            if name.startswith("sinterheat") and target.split(".")[0] != "sinterheat":
                wrong.append(where)
    assert not wrong, "\n".join(wrong)


@pytest.mark.slow
def test_every_name_defined_is_used_somewhere():
    """A function, class, constant or method that no other line of the repository (code, tests, examples, README,
    documentation) names is dead code."""
    texts = [p.read_text() for p in modules().values()]
    for folder, pattern in (("tests", "*.py"), ("examples", "*.py"), ("docs", "*.rst"), ("docs", "*.md"),
                            ("docs", "*.py")):
        texts += [p.read_text() for p in (ROOT / folder).rglob(pattern) if "_build" not in p.parts]
    texts.append((ROOT / "README.md").read_text())
    count: dict = {}
    for text in texts:
        for word in re.findall(r"[A-Za-z_][A-Za-z0-9_]*", text):
            count[word] = count.get(word, 0) + 1
    dead = []
    for name, path in modules().items():
        for node in ast.parse(path.read_text()).body:
            defined = []
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                defined = [node.name]
                if isinstance(node, ast.ClassDef):
                    defined += [f"{node.name}.{m.name}" for m in node.body if isinstance(m, ast.FunctionDef)]
            elif isinstance(node, ast.Assign):
                defined = [t.id for t in node.targets if isinstance(t, ast.Name)]
            for full in defined:
                word = full.rpartition(".")[2]
                if not word.startswith("__") and count.get(word, 0) <= 1:
                    dead.append(f"{path.relative_to(ROOT)}: {full}")
    assert not dead, "defined but named nowhere else:\n" + "\n".join(dead)


def parameter_count(node: ast.FunctionDef) -> int:
    """The parameters ``node`` takes, ``*args`` and ``**kwargs`` counting one each."""
    a = node.args
    return len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None) + (a.kwarg is not None)


def test_no_function_of_dem_takes_more_than_sixteen_parameters():
    """Particles, pairs, walls and parameters go to a function as records, not as long argument lists (methods and
    nested functions included)."""
    over = set()
    for path in (ROOT / "dem").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and parameter_count(node) > MAX_PARAMETERS:
                over.add(f"{path.relative_to(ROOT).as_posix()}:{node.name}")
    assert not over, f"more than {MAX_PARAMETERS} parameters: {sorted(over)}"


def test_the_parameter_count_sees_every_kind_of_parameter():
    node = ast.parse("def f(a, /, b, *c, d, **e): pass").body[0]
    assert parameter_count(node) == 5
