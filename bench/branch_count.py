"""Count the branch tests that name a MuJoCo model kind or finite grip outside that kind's own modules.

The measure of how well the engine's seam holds (a kind's concerns live in its own modules, not as flags
threaded through the rest): every ``if``/``elif``/``while`` test, conditional expression and comprehension
filter of the package's source (``ipir_mujoco/`` and ``analytic/``) whose text names finite grip (``grip``,
``mu_wall``, ``has_grip``, ``skid_q``, the grip controllers) or the wheeled model (``wheeled``, ``'wheels'``,
``WHEELS``, ``WheelRatchet``), leaving out the kinds' own modules (``engine/modelkinds/kinds.py``; finite grip's
``*grip*.py``; the wheels' ``wheels*.py``, ``route_*.py``, ``pipe_*.py``). Run from the repository root:

    python bench/branch_count.py [ROOT] [-v] [--smoke]

``-v`` lists each test (file:line, which concern, its text). ``--smoke`` changes nothing (the count takes
seconds already); it is there because every bench takes it.

A kind's own modules are its own whichever concern their text names: the wheels' modules test ``mu_wall``, the
friction of the wheels' contacts, as the wheeled kind's own parameter.

The tests found are reported by where they stand, each group with why its tests are there:

- ``engine``: the MuJoCo run path (``engine/``, ``registry.py``, the viewer): what the seam is for; the tests
  left are listed with their reason in docs/architecture.md ("Branches on a kind left outside the kinds").
- ``analytic``: the analytic model choosing its own model from the parameters (``analytic/__init__.py``,
  the run loops): the analytic side's counterpart of ``kind_for``; it has no seam with the engine by design.
- ``core``: the parameter's own definition and checks (``core/params.py``), the grip-use figure, the pipe fit.
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
KINDS = re.compile(r"(^|/)engine/(modelkinds/)?kinds\.py$")  # the kinds' module, before and after the regroup


def count(root: Path) -> dict[str, list[tuple[str, int, str]]]:
    """{'grip': [...], 'wheels': [...]}: each branch test as (file, line, text)."""
    found: dict[str, list] = {"grip": [], "wheels": []}
    for file in sorted([*(root / "ipir_mujoco").rglob("*.py"), *(root / "analytic").rglob("*.py")]):
        rel = file.relative_to(root).as_posix()
        if KINDS.search(rel):
            continue
        source = file.read_text()
        for node in ast.walk(ast.parse(source)):
            tests = [node.test] if isinstance(node, (ast.If, ast.IfExp, ast.While)) else (
                list(node.ifs) if isinstance(node, ast.comprehension) else [])
            for test in tests:
                text = ast.get_source_segment(source, test) or ""
                for concern, pattern in (("grip", GRIP), ("wheels", WHEELS)):
                    if pattern.search(text) and not any(own.search(rel) for own in OWN.values()):
                        found[concern].append((rel, node.lineno, text))
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
    found = count(Path(args[0]) if args else Path("."))
    files = {f for items in found.values() for f, _, _ in items}
    print(f"grip {len(found['grip'])}, wheels {len(found['wheels'])}, total "
          f"{sum(len(v) for v in found.values())} in {len(files)} files")
    by_group = {}
    for items in found.values():
        for rel, line, _ in items:
            by_group.setdefault(group(rel), set()).add((rel, line))
    print("  by group (module docstring): " + ", ".join(f"{name} {len(by_group.get(name, ()))}"
                                                      for name, _ in GROUPS))
    if "-v" in sys.argv:
        for concern, items in found.items():
            for rel, line, text in items:
                print(f"  {rel}:{line} [{concern}] {' '.join(text.split())[:90]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
