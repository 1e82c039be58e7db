"""Count the branch tests that name a model kind or a clutch controller where they do not belong.

Two measures of how well the engine's seam holds (a kind's concerns live in its own folder, a controller's in
its protocol members, not as flags threaded through the rest). Run from the repository root:

    python bench/branch_count.py [ROOT] [-v] [--smoke]

``-v`` lists each test (file:line, which concern, its text). ``--smoke`` changes nothing (the count takes
seconds already); it is there because every bench takes it.

**The run path** (issue 51: 0): every ``if``/``elif``/``while`` test, conditional expression and comprehension
filter of ``engine/loop/`` and ``engine/run/`` (Python), and every ``if``, ``while`` and ``?:`` condition of
``engine/loop/*.c``, whose text names a model kind or finite grip (``kind``, ``grip``, ``mu_wall``, the wheels,
the slides, :data:`KIND_WORDS`) or a controller (``controller``/``ctl``, the compliant clutch, ``deferred``, the
work rates' ``power``, a controller's optional member: :data:`CONTROLLER_WORDS`). What differs by kind is asked of
the kind (``engine/kinds/<kind>/``), what differs by controller of the controller (its protocol,
``engine/loop/controller.py``): the loop and the run hold no test on which one runs.

**The whole package** (the measure since issue 31): every such Python test of ``ipir_mujoco/`` and ``analytic/``
whose text names finite grip (``grip``, ``mu_wall``, ``has_grip``, ``skid_q``, the grip controllers) or the
wheeled model (``wheeled``, ``'wheels'``, ``WHEELS``, ``WheelRatchet``), leaving out the kinds' own modules
(everything under ``engine/kinds/``: each kind's folder and what the kinds share) and the analytic model's own
modules of an effect (``*grip*.py``). Reported by where they stand, each group with why its tests are there:

- ``engine``: the MuJoCo engine outside the kinds (``engine/``, ``registry.py``, the viewer): what the seam is for;
  the tests left are listed with their reason in docs/architecture.md ("Branches on a kind left outside the
  kinds").
- ``analytic``: the analytic model choosing its own model from the parameters (``analytic/__init__.py``,
  the run loops): the analytic side's counterpart of ``kind_for``; it has no seam with the engine by design.
- ``core``: the parameter's own definition and checks (``core/param_table.py``), the grip-use figure, the pipe fit.
- ``studies``: studies, reports and their command-line output whose subject is finite grip (traction,
  climbing, bends, the atlas's axes).
- ``drawing``: the replay, the video and ``render`` drawing the wheeled model's legs or the slide model.
"""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

GRIP = re.compile(r"\bgrip\b|mu_wall|has_grip|skid_q|\bGRIP_SLIDES\b|GripRatchet|CompliantGrip")
WHEELS = re.compile(r"wheeled|[\"']wheels[\"']|\bWHEELS\b|is_wheeled|WheelRatchet")
OWN = {"grip": re.compile(r"(^|/)(grip[^/]*|[^/]*_grip)\.py$"),
       "wheels": re.compile(r"(^|/)(wheels[^/]*|route_\w+|pipe_\w+)\.py$")}
# the kinds' own modules: engine/kinds/ (each kind's folder, what kinds share), and the kinds' module before it
KINDS = re.compile(r"(^|/)engine/(kinds/|(modelkinds/)?kinds\.py$)")

# the run path's words for a kind (an attribute of a kind object, the kinds' registry, finite grip, the wheels) and
# for a controller (an attribute of the controller, the compliant clutch, the work rates' power, the members a
# controller may lack); a local name or attribute assigned one of them (not a call's result, but getattr's) counts
# as one (``after = ctl.after_step``, ``self.clutch = controller if controller.deferred else None``)
KIND_WORDS = re.compile(r"\bkind\.|kind_for|KINDS|SLIDE_KIND|GRIP_SLIDES|\bWHEELS\b|\bgrip\b|has_grip|mu_wall|wheel|"
                        r"skid_rule|verifies_skids|pipe_built")
CONTROLLER_WORDS = re.compile(r"controller\.|\bctl\.|\bclutch\b|compliant|clutch_stiffness|\.deferred\b|\bpower\b|"
                              r"_own_work|after_step|before_step|load_compiled|getattr\(\s*(ctl|controller)")
RUN_PATH = re.compile(r"^ipir_mujoco/engine/(loop|run)/")
C_CONDITION = re.compile(r"\b(if|while)\s*\((?P<test>.*)\)|(?P<ternary>[^;]*\?)")
C_WORDS = re.compile(r"ctl->\w+\s*[!=]=\s*NULL|NULL\s*[!=]=\s*ctl->|CONTROLLER\([^)]*\)\s*[!=]=|grip|wheel|compliant|"
                     r"\bdeferred\b|nfric")


def _aliases(source: str, words: re.Pattern) -> re.Pattern:
    """``words`` and the names (or attributes) ``source`` assigns from an expression naming one of them."""
    names = set()
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.Assign):
            continue
        pairs = []
        for target in node.targets:
            if isinstance(target, ast.Tuple) and isinstance(node.value, ast.Tuple) \
                    and len(target.elts) == len(node.value.elts):
                pairs += zip(target.elts, node.value.elts)
            else:
                pairs.append((target, node.value))
        for target, value in pairs:
            text = ast.get_source_segment(source, value) or ""
            called = isinstance(value, ast.Call) and not (isinstance(value.func, ast.Name) and value.func.id == "getattr")
            if isinstance(target, (ast.Name, ast.Attribute)) and not called and words.search(text):
                names.add(re.escape(ast.get_source_segment(source, target) or ""))
    names.discard("")
    return re.compile("|".join([words.pattern, *(rf"(?<![\w.]){n}\b" for n in sorted(names))]))


def _tests(source: str):
    """(line, test text) of every branch test of ``source``: if/elif/while tests, conditional expressions,
    comprehension filters."""
    for node in ast.walk(ast.parse(source)):
        tests = [node.test] if isinstance(node, (ast.If, ast.IfExp, ast.While)) else (
            list(node.ifs) if isinstance(node, ast.comprehension) else [])
        for test in tests:
            yield test.lineno, ast.get_source_segment(source, test) or ""


def count(root: Path) -> dict[str, list[tuple[str, int, str]]]:
    """{'grip': [...], 'wheels': [...]}: each branch test of the whole package as (file, line, text)."""
    found: dict[str, list] = {"grip": [], "wheels": []}
    for file in sorted([*(root / "ipir_mujoco").rglob("*.py"), *(root / "analytic").rglob("*.py")]):
        rel = file.relative_to(root).as_posix()
        if KINDS.search(rel) or any(own.search(rel) for own in OWN.values()):
            continue
        for line, text in _tests(file.read_text()):
            for concern, pattern in (("grip", GRIP), ("wheels", WHEELS)):
                if pattern.search(text):
                    found[concern].append((rel, line, text))
    return found


def run_path(root: Path) -> dict[str, list[tuple[str, int, str]]]:
    """{'kind': [...], 'controller': [...]}: each branch test of engine/loop/ and engine/run/ (Python and C) naming
    a kind or a controller, as (file, line, text)."""
    found: dict[str, list] = {"kind": [], "controller": []}
    engine = root / "ipir_mujoco" / "engine"
    for file in sorted([*(engine / "loop").glob("*.py"), *(engine / "run").glob("*.py")]):
        rel, source = file.relative_to(root).as_posix(), file.read_text()
        words = (("kind", _aliases(source, KIND_WORDS)), ("controller", _aliases(source, CONTROLLER_WORDS)))
        for line, text in _tests(source):
            for concern, pattern in words:
                if pattern.search(text):
                    found[concern].append((rel, line, text))
    for file in sorted((engine / "loop").glob("*.c")):
        rel = file.relative_to(root).as_posix()
        for line, text in enumerate(file.read_text().splitlines(), start=1):
            code = text.split("//")[0].split("/*")[0]
            match = C_CONDITION.search(code)
            if match and C_WORDS.search(match.group("test") or match.group("ternary") or ""):
                found["controller"].append((rel, line, code.strip()))
    return found


GROUPS = (  # (group, where: a path pattern), the first that matches
    ("engine", re.compile(r"^ipir_mujoco/(engine/|registry\.py$|cli/view\.py$|view\.py$)")),
    ("analytic", re.compile(r"^analytic/")),
    ("core", re.compile(r"^ipir_mujoco/core/")),
    ("drawing", re.compile(r"^ipir_mujoco/(replay|video)\.py$|^ipir_mujoco/cli/render\.py$")),
    ("studies", re.compile(r"")),
)


def group(rel: str) -> str:
    """The group (module docstring) of a file's tests."""
    return next(name for name, where in GROUPS if where.search(rel))


def main() -> int:
    if "-h" in sys.argv or "--help" in sys.argv:
        print(__doc__)
        return 0
    # the options by hand (no argparse): a ROOT, -v, and --smoke, which every bench takes
    args = [a for a in sys.argv[1:] if a not in ("-v", "--smoke")]
    root = Path(args[0]) if args else Path(".")
    seam = run_path(root)
    lines = {(rel, line) for items in seam.values() for rel, line, _ in items}
    print(f"run path (engine/loop, engine/run): {len(lines)} tests on a kind or a controller (kind "
          f"{len(seam['kind'])}, controller {len(seam['controller'])})")
    found = count(root)
    files = {f for items in found.values() for f, _, _ in items}
    print(f"whole package: grip {len(found['grip'])}, wheels {len(found['wheels'])}, total "
          f"{sum(len(v) for v in found.values())} in {len(files)} files")
    by_group = {}
    for items in found.values():
        for rel, line, _ in items:
            by_group.setdefault(group(rel), set()).add((rel, line))
    print("  by group (module docstring): " + ", ".join(f"{name} {len(by_group.get(name, ()))}"
                                                      for name, _ in GROUPS))
    if "-v" in sys.argv:
        for concern, items in [*seam.items(), *found.items()]:
            for rel, line, text in items:
                print(f"  {rel}:{line} [{concern}] {' '.join(text.split())[:90]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
