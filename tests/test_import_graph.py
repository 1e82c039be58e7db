"""No import cycle among the package's modules, the imports inside functions included.

A function-level import only postpones a cycle to the first call, where a half-initialised module can still
surface; so every ``import`` and ``from ... import`` the source holds counts here, wherever it stands, except
those under ``if TYPE_CHECKING:`` (never executed: annotations only). An edge goes from a module to each
package module it names (``from .x import y`` names ``x``, or ``x.y`` where that is a module). The source is
read, not imported: the repository's ``analytic/`` folder is ``ipir_mujoco.analytic``.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TREES = {"ipir_mujoco": ROOT / "ipir_mujoco", "ipir_mujoco.analytic": ROOT / "analytic"}


def modules() -> dict[str, tuple[Path, bool]]:
    """{dotted name: (file, is a package's __init__)} of every module of the package."""
    found = {}
    for prefix, folder in TREES.items():
        for file in folder.rglob("*.py"):
            parts = list(file.relative_to(folder).with_suffix("").parts)
            package = parts[-1] == "__init__"
            if package:
                parts = parts[:-1]
            found[".".join([prefix, *parts])] = (file, package)
    return found


def _type_checking(node: ast.AST) -> bool:
    test = getattr(node, "test", None)
    return isinstance(node, ast.If) and (
        (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING")
        or (isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"))


def _imports(tree: ast.AST):
    """Every import statement of ``tree`` outside ``if TYPE_CHECKING:`` blocks."""
    stack = [tree]
    while stack:
        node = stack.pop()
        if _type_checking(node):
            stack.extend(node.orelse)
            continue
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        stack.extend(ast.iter_child_nodes(node))


def graph() -> dict[str, set[str]]:
    """{module: the package modules it imports}."""
    known = modules()
    edges: dict[str, set[str]] = {name: set() for name in known}
    for name, (file, package) in known.items():
        here = name.split(".") if package else name.split(".")[:-1]
        for node in _imports(ast.parse(file.read_text())):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                base = ".".join(here[:len(here) - node.level + 1] + ([node.module] if node.module else [])) \
                    if node.level else node.module or ""
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in node.names]
            edges[name] |= {t for t in targets if t in known and t != name}
    return edges


def cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    index, low, on, stack, found, counter = {}, {}, set(), [], [], [0]
    for root in edges:
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter[0]
                    counter[0] += 1
                    stack.append(child)
                    on.add(child)
                    work.append((child, iter(sorted(edges[child]))))
                elif child in on:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def test_the_finder_sees_every_kind_of_import():
    """The graph holds top-level, relative, function-level and package-level imports (so the test below has
    edges to look at), and leaves out TYPE_CHECKING ones."""
    edges = graph()
    assert len(edges) > 100
    assert "ipir_mujoco.engine.kinds" in edges["ipir_mujoco.engine.run.simulate"]  # relative, top level
    assert "ipir_mujoco.engine.kinds" in edges["ipir_mujoco.registry"]  # inside registry.timestep
    assert "ipir_mujoco.core.figures" in edges["ipir_mujoco.core.results"]  # inside RunResult.plot
    assert "ipir_mujoco.core.results" not in edges["ipir_mujoco.core.figures"]  # TYPE_CHECKING only
    assert "ipir_mujoco.studies.design.calibrate" in edges["ipir_mujoco.studies.design.calibrate_command"]  # in run
    assert "ipir_mujoco.analytic.kinematic_clutch" in edges["ipir_mujoco.analytic"]  # the analytic/ folder


def test_cycles_are_found():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_cycle_among_the_packages_modules():
    assert cycles(graph()) == []


def test_the_architecture_document_places_every_module_of_the_engine_core_and_analytic_model():
    """docs/architecture.md names each module of the engine (each kind's folder's too), the core, the analytic
    model and the package's top level (the studies', report's and command line's are placed there by group)."""
    text = (ROOT / "docs" / "architecture.md").read_text()
    engine = ROOT / "ipir_mujoco" / "engine"
    folders = (engine, *sorted(p.parent for p in engine.rglob("__init__.py") if p.parent != engine),
               ROOT / "ipir_mujoco" / "core", ROOT / "analytic", ROOT / "ipir_mujoco")
    missing = [f"{folder.name}/{file.name}" for folder in folders for file in sorted(folder.glob("*.py"))
               if file.name not in ("__init__.py", "__main__.py") and file.name not in text]
    assert missing == []
    assert [f"engine/{folder}/" for folder in ENGINE_FOLDERS if f"engine/{folder}/" not in text] == []
    kinds = sorted(p.parent.name for p in (engine / "kinds").glob("*/__init__.py"))
    assert [f"engine/kinds/{kind}/" for kind in kinds if f"engine/kinds/{kind}/" not in text] == []


# the package's layers from the bottom up (docs/architecture.md, "The layers"): a module imports from its own layer
# and the layers below only. The package's __init__ imports only core at its top (its public names load on first
# use), so it stands with core; labels, output, resources, interrupts and terminal are the tools every layer uses.
LAYERS = (
    ("ipir_mujoco", "ipir_mujoco.core", "ipir_mujoco.labels", "ipir_mujoco.output", "ipir_mujoco.resources",
     "ipir_mujoco.interrupts", "ipir_mujoco.terminal"),
    ("ipir_mujoco.analytic", "ipir_mujoco.engine"),
    ("ipir_mujoco.registry", "ipir_mujoco.variants", "ipir_mujoco.feedforward", "ipir_mujoco.replay",
     "ipir_mujoco.video"),
    ("ipir_mujoco.studies",),
    ("ipir_mujoco.report",),
    ("ipir_mujoco.cli", "ipir_mujoco.view", "ipir_mujoco.__main__"),
)


def package_layer(module: str) -> int:
    """The index in LAYERS of ``module``'s layer: the layer of the longest prefix that names it."""
    found = [(len(prefix), i) for i, layer in enumerate(LAYERS) for prefix in layer
             if module == prefix or module.startswith(prefix + ".")]
    assert found, f"{module} is in no layer of LAYERS"
    return max(found)[1]


def test_no_module_imports_a_layer_above_it():
    """No module of the package imports one of a layer above its own, the imports inside functions included (a
    study that drew its figure by importing the report inside its run function was such an edge: it is given its
    report module by the command line now, ipir_mujoco.studies.contract)."""
    edges = graph()
    upward = sorted((name, target) for name, targets in edges.items() for target in targets
                    if package_layer(target) > package_layer(name))
    assert upward == []
    # the edges looked at include function-level ones across layers (validate's command imports the report
    # inside its run), and an edge the other way would count as upward
    assert "ipir_mujoco.report.sections" in edges["ipir_mujoco.cli.validate"]
    assert package_layer("ipir_mujoco.cli.validate") > package_layer("ipir_mujoco.report.sections") \
        > package_layer("ipir_mujoco.studies.validation.validate")


# the engine's folders from the bottom up: a module imports from its own folder and the folders below only
ENGINE_FOLDERS = ("builders", "loop", "controllers", "kinds", "run")


def test_the_engines_folders_import_downward_only():
    """Each engine module imports only modules of its own folder or of a folder below it (the engine's top level,
    ``__init__`` and the older path ``clutches``, stands above them all)."""
    def layer(module: str) -> int | None:
        parts = module.split(".")
        if parts[:2] != ["ipir_mujoco", "engine"] or len(parts) < 4:
            return None
        return ENGINE_FOLDERS.index(parts[2])
    upward = [(name, target) for name, targets in graph().items() if layer(name) is not None
              for target in targets if layer(target) is not None and layer(target) > layer(name)]
    assert upward == []
    # every folder of the engine is in the order above, and no module of the engine sits outside them but two
    found = {p.name for p in (ROOT / "ipir_mujoco" / "engine").iterdir() if (p / "__init__.py").is_file()}
    assert found == set(ENGINE_FOLDERS)
    loose = sorted(p.name for p in (ROOT / "ipir_mujoco" / "engine").glob("*.py"))
    assert loose == ["__init__.py", "clutches.py"]
