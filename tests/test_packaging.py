"""The installed package: one top-level name, data files reachable, the two models independent."""

from __future__ import annotations

import pytest

import ast
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import ipir_mujoco
from ipir_mujoco import analytic
from ipir_mujoco.resources import docs_dir, mjcf_dir, shipped


def _imports(path: Path, package: str) -> list[str]:
    """Absolute names of every module ``path`` imports (relative imports resolved against ``package``)."""
    names = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".")
                base = parts[: len(parts) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            names.append(module)
            names += [f"{module}.{alias.name}" for alias in node.names]
    return names


def test_mjcf_folder_is_reachable():
    assert (mjcf_dir() / "README.md").is_file()
    assert (docs_dir() / "model.md").is_file()
    assert Path(shipped("docs/model.md")) == docs_dir() / "model.md"


PACKAGE = Path(ipir_mujoco.__file__).resolve().parent


def _layer_imports(folder: Path, package: str) -> list[tuple[str, str]]:
    """(file name, imported module) for every module the .py files of ``folder`` import."""
    files = sorted(folder.glob("*.py"))
    assert files, folder
    return [(path.name, name) for path in files for name in _imports(path, package)]


def test_analytic_never_imports_mujoco_or_the_physics_side():
    """The cross-check is worthless if the analytic side borrows the physics side's code: of ipir_mujoco it
    imports only itself and the shared vocabulary (ipir_mujoco.core)."""
    for file, name in _layer_imports(Path(analytic.__file__).parent, "ipir_mujoco.analytic"):
        assert name.split(".")[0] != "mujoco", f"{file} imports {name}"
        if name.startswith("ipir_mujoco."):
            assert name.startswith(("ipir_mujoco.analytic", "ipir_mujoco.core")), f"{file} imports {name}"


def test_the_shared_core_imports_neither_model():
    """ipir_mujoco.core is what both models share: the parameter set, the result container, the errors and
    the per-revolution figures. It imports no engine, no MuJoCo, no scipy: nothing that computes dynamics."""
    import ipir_mujoco.core

    for file, name in _layer_imports(Path(ipir_mujoco.core.__file__).parent, "ipir_mujoco.core"):
        assert name.split(".")[0] not in ("mujoco", "scipy"), f"{file} imports {name}"
        if name.startswith("ipir_mujoco."):
            assert name.startswith("ipir_mujoco.core"), f"{file} imports {name}"


def test_importing_the_analytic_package_does_not_load_mujoco():
    code = "import sys, ipir_mujoco.analytic; assert 'mujoco' not in sys.modules, sorted(sys.modules)"
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)


def test_the_mujoco_side_never_runs_the_analytic_equations():
    """The MuJoCo engine shares the parameter set, the result container, the errors and the per-revolution
    figures (ipir_mujoco.core) with the analytic package, and imports nothing of the analytic package itself,
    nor of the layers above it."""
    import ipir_mujoco.engine

    for file, name in _layer_imports(Path(ipir_mujoco.engine.__file__).parent, "ipir_mujoco.engine"):
        assert not (name == "ipir_mujoco.analytic" or name.startswith("ipir_mujoco.analytic.")), \
            f"{file} imports {name}"
        assert not name.startswith(("ipir_mujoco.studies", "ipir_mujoco.report", "ipir_mujoco.cli")), \
            f"the engine layer {file} imports the layer above it: {name}"


def test_studies_and_report_never_import_the_command_line():
    """The command line sits on top: studies and the report are usable from Python without it."""
    for layer in ("studies", "report"):
        for file, name in _layer_imports(PACKAGE / layer, f"ipir_mujoco.{layer}"):
            assert not name.startswith("ipir_mujoco.cli"), f"{layer}/{file} imports {name}"


@pytest.mark.slow
def test_a_local_analytic_module_does_not_shadow_the_package(tmp_path):
    """A user's own analytic.py in the working directory must not break the tool."""
    (tmp_path / "analytic.py").write_text("raise ImportError('this is the user\\'s own module')\n")
    done = subprocess.run([sys.executable, "-m", "ipir_mujoco", "--version"], cwd=tmp_path,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


REPOSITORY = Path(__file__).resolve().parent.parent


def test_import_analytic_alone_fails_outside_a_checkout(tmp_path):
    """The distribution owns one top-level name: 'analytic' is not installed as a package of its own."""
    done = subprocess.run([sys.executable, "-c", "import analytic"], cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode != 0 and "No module named 'analytic'" in done.stderr


def test_docs_and_code_point_only_inside_the_repository():
    """README, docs, code, tests and the MJCF never send a user to files the package does not ship."""
    forbidden = ("shared" "/", "MODEL" ".md", "CONTRACT" ".md", "DESIGN" ".md")  # in pieces: see test_validate
    files = [REPOSITORY / "README.md"]
    for folder, pattern in (("docs", "*.md"), ("ipir_mujoco", "*.py"), ("analytic", "*.py"), ("tests", "*.py"),
                            ("mjcf", "*")):
        files += [p for p in (REPOSITORY / folder).rglob(pattern) if p.is_file() and "__pycache__" not in p.parts]
    files = [p for p in files if p.suffix != ".png"]
    assert len(files) > 40
    hits = [f"{p.relative_to(REPOSITORY)}: {word}" for p in files
            for word in forbidden if word in p.read_text(encoding="utf-8")]
    assert not hits


def test_readme_keeps_the_fresh_machine_commands():
    """CI (.ci/run) runs the README's second command line; the first is what a new user types."""
    lines = (REPOSITORY / "README.md").read_text().splitlines()
    assert "    python3 -m venv .venv && . .venv/bin/activate && pip install . && ipir-mujoco validate" in lines[:8]
    assert "    python3 -m venv .venv && . .venv/bin/activate && pip install '.[test]' && pytest" in lines[:8]


def test_package_metadata():
    import tomllib

    project = tomllib.loads((REPOSITORY / "pyproject.toml").read_text())["project"]
    assert project["license"] == "MIT" and (REPOSITORY / "LICENSE").read_text().startswith("MIT License")
    assert project["authors"] == [{"name": "ipir-mujoco developers"}]
    mujoco = next(r for r in project["dependencies"] if r.startswith("mujoco"))
    assert "<5" in mujoco  # 4.x is what the suite runs on; a new major version must be tested first
    extras = project["optional-dependencies"]
    # the Dask scheduler is its own extra; the test extra pulls it in only for the Dask test of sweep
    assert any(r.startswith("dask[distributed]") for r in extras["dask"])
    assert "ipir-mujoco[dask]" in extras["test"] and not any(r.startswith("dask") for r in extras["test"])
    # what the validation report and the atlas use is installed by the README's plain `pip install .`: SALib
    # (their Sobol indices, the report's "driven by" column), unconditionally
    assert any(r.startswith("SALib>=") and ";" not in r for r in project["dependencies"])


def _printed_text(path: Path) -> list[str]:
    """The string literals of a module that are not docstrings (f-strings' literal parts included): what its
    messages, help and reports can print."""
    tree = ast.parse(path.read_text())
    docstrings = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                docstrings.add(id(first.value))
    return [node.value for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings]


# repository files a user with only the wheel lacks (README.md at the top, not mjcf/README.md)
REPOSITORY_ONLY = re.compile(r"(?<![\w/])(README\.md|bench/|tests/|setup\.py|pyproject\.toml)")
DOCUMENT = re.compile(r"(?<![\w/])((?:docs|mjcf)/[\w.-]+\.\w+)")  # a shipped folder's file, as named


def _holds_build_requirements() -> bool:
    """Whether this environment satisfies pyproject.toml's [build-system] requires (each name installed, at a
    version its specifier allows)."""
    import tomllib
    from importlib.metadata import PackageNotFoundError, version

    from packaging.requirements import Requirement

    for text in tomllib.loads((REPOSITORY / "pyproject.toml").read_text())["build-system"]["requires"]:
        requirement = Requirement(text)
        try:
            if not requirement.specifier.contains(version(requirement.name), prereleases=True):
                return False
        except PackageNotFoundError:
            return False
    return True


@pytest.mark.slow
def test_the_wheel_ships_every_document_the_output_names(tmp_path):
    """Built from a clean copy of the checkout, the wheel holds the user docs (ipir_mujoco/docs) and the MJCF
    folder; every docs/ or mjcf/ file the program's messages, help or report name is in it, their relative
    links resolve inside it, and no printed text sends a user to a file only the repository has."""
    source = tmp_path / "src"
    built = shutil.ignore_patterns(".git", "build", "dist", "*.egg-info", "__pycache__", "*.so", ".pytest_cache",
                                   ".hypothesis")

    def ignored(folder, names):  # and at the top, what a checkout gathers: the README's .venv (900 MB, 10 s)
        top = {".venv", "venv", "report"} & set(names) if Path(folder) == REPOSITORY else set()
        return built(folder, names) | top
    shutil.copytree(REPOSITORY, source, ignore=ignored)
    # built in this environment where it holds pyproject.toml's build requirements (the test extra installs
    # setuptools>=77; mujoco is a dependency): an isolated build installs them afresh, about 15 s of the test
    isolation = ["--no-build-isolation"] if _holds_build_requirements() else []
    done = subprocess.run([sys.executable, "-m", "pip", "wheel", str(source), "--no-deps", "-q", "-w",
                           str(tmp_path / "wheel"), *isolation], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    (wheel,) = (tmp_path / "wheel").glob("ipir_mujoco-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    for doc in ("docs/cli.md", "docs/model.md", "docs/citing.md", "docs/mechanism.png", "mjcf/README.md",
                "mjcf/inchworm.xml"):
        assert f"ipir_mujoco/{doc}" in names, doc
    if shutil.which(sysconfig.get_config_var("CC").split()[0]):  # built against the build env's mujoco
        assert any(n.startswith("ipir_mujoco/engine/loop/_stepper.") for n in names), sorted(names)
        assert any(n.startswith("ipir_mujoco/engine/builders/_pipewall.") for n in names), sorted(names)
    named, misdirected = set(), []
    for path in sorted((REPOSITORY / "ipir_mujoco").rglob("*.py")) + sorted((REPOSITORY / "analytic").rglob("*.py")):
        for text in _printed_text(path):
            named.update(DOCUMENT.findall(text))
            misdirected += [f"{path.name}: {hit}" for hit in REPOSITORY_ONLY.findall(text)]
    assert {"docs/model.md", "mjcf/README.md"} <= named  # the validation report's, at least
    assert not [n for n in named if f"ipir_mujoco/{n}" not in names]
    assert not misdirected
    for page in [n for n in names if n.startswith("ipir_mujoco/docs/") and n.endswith(".md")]:
        text = zipfile.ZipFile(wheel).read(page).decode()
        for target in re.findall(r"\]\(([^)#]+)\)", text):
            if not target.startswith("http"):
                resolved = (Path(page).parent / target).as_posix().split("/")
                while ".." in resolved:  # fold "a/../" away
                    i = resolved.index("..")
                    del resolved[i - 1:i + 1]
                assert "/".join(resolved) in names, f"{page} links to {target}"
