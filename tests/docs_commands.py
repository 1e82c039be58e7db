"""The commands the documentation shows, extracted so that a test can run each (tests/test_docs_commands.py).

Where commands are found (every user-facing page and file header):

- README.md, docs/*.md, mjcf/README.md: code blocks (lines indented 4 spaces or more, or inside a ``` fence)
  whose line starts with ``ipir-mujoco `` or ``python `` (after an optional ``$ `` prompt; a line ending in
  ``\\`` continues on the next), and inline code spans that start so (```ipir-mujoco climb --drive motor```);
- mjcf/*.toml: the header comment (the leading ``#`` lines), read as Markdown;
- bench/*.py, ipir_mujoco/**/*.py and analytic/*.py: the module docstring, read as Markdown (double
  backticks for inline spans).

What a command is:

- a synopsis (it holds ``[``, ``|``, ``...`` or a placeholder in capitals such as ``FILE.toml`` or
  ``NAME=VALUE``, outside quotes): the test runs its ``--help`` and checks that every option it shows is
  in the help;
- ``$ COMMAND`` followed, in the same block, by lines that are not commands: those lines are the quoted
  output, which the command's output must hold, line for line (a line of ``...`` stands for lines left out;
  wall times, ``(0.26 s wall)``, are not compared);
- a command named in running text or a heading without arguments (```ipir-mujoco clutch-study```: the
  engagement loads ...; ``python -m ipir_mujoco.studies.convergence``) is a name: its ``--help`` runs
  (the command's synopsis and examples in code blocks run where they stand); a benchmark named so runs;
- a command that reads a file the pages do not make (``--data run.csv``) runs its ``--help``;
- anything else runs as written, with these shortenings (said so in docs/cli.md, "Every documented command
  is tested"): a benchmark (``python bench/NAME.py``) gets ``--smoke``, a command that takes ``--quick``
  gets it, ``--samples`` and ``--budget`` above 16 and ``--mujoco-samples`` above 3 are cut to that, a
  command that leaves ``--samples`` or ``--budget`` (where it has them) at its default runs with
  ``--samples 16``, ``--budget 8``, a video (``render``) is made at ``--fps 5``, and in a block that quotes
  no output a grid (``--vary NAME=LO:HI:N``) of more than 8 points runs with 8; a shortened command's output
  is not compared.

Commands of one file run in their order in one scratch folder holding copies of mjcf/ and docs/ and the
bench/ and tests/ folders (so that ``--out sizing`` then ``python -c ... open('sizing/results.csv')``
work); identical commands of one file run once. Commands that need a screen (``python -m
ipir_mujoco.view``, MuJoCo's own viewer) run without one and must refuse in one line with exit 2.
"""

from __future__ import annotations

import ast
import re
import shlex
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PREFIX = re.compile(r"^(?:\$ )?(ipir-mujoco|python3?)(?= |$)")
# a segment of a shell line that sets up an environment: listed, not run (the test runs in one already)
SETUP = re.compile(r"^\s*(pip |\. |source |python3? -m venv)")


@dataclass
class Command:
    source: str                       # "README.md:95"
    text: str                         # as documented, continuation lines joined, prompt and comments removed
    output: list[str] = field(default_factory=list)   # the quoted output lines (after a "$ " prompt)
    inline: bool = False
    group: str = ""                   # its code block or paragraph: commands of one group run in order
    heading: bool = False             # shown in a heading ('## `ipir-mujoco sweep`'): the command's name

    @property
    def synopsis(self) -> bool:
        """A usage line (options in brackets, alternatives, placeholders), not a command to run as written."""
        bare = re.sub(r"'[^']*'|\"[^\"]*\"", "", self.text)
        return bool(re.search(r"[\[\]|]|\.\.\.|\b[A-Z][A-Z0-9_]*[A-Z](?![a-z])", bare)
                    and not re.search(r"\|\s*(diff|head|tail|grep)\b", bare))

    @property
    def screen(self) -> bool:
        """Needs a screen: MuJoCo's viewer, ours or MuJoCo's own."""
        return bool(re.search(r"-m (ipir_mujoco\.view|mujoco\.viewer)\b", self.text))

    @property
    def setup(self) -> bool:
        return bool(SETUP.match(self.text))


def _strip_comment(line: str) -> str:
    """The line without a shell comment ('  # or .mp4 with: ...') outside quotes."""
    quote = None
    for i, ch in enumerate(line):
        if ch in "'\"":
            quote = None if quote == ch else (quote or ch)
        elif ch == "#" and quote is None and (i == 0 or line[i - 1] == " "):
            return line[:i].rstrip()
    return line.rstrip()


def _commands_in_line(text: str) -> list[str]:
    """The runnable segments of a shell line: 'python3 -m venv .venv && ... && ipir-mujoco validate' gives
    the ipir-mujoco part (setup segments are left out, run in the test's own environment)."""
    parts = [p.strip() for p in re.split(r"\s&&\s", text)]
    if len(parts) > 1 and any(SETUP.match(p) for p in parts):
        return [p for p in parts if not SETUP.match(p) and PREFIX.match(p)]
    return [text]


def _open_quote(text: str) -> bool:
    """Whether a shell line ends inside a quoted string (it goes on on the next line)."""
    try:
        shlex.split(text)
    except ValueError:
        return True
    return False


def parse(text: str, source: str, first_line: int = 1, double_ticks: bool = False) -> list[Command]:
    """Every command in ``text`` (Markdown), numbered from ``first_line``."""
    lines = text.splitlines()
    found: list[Command] = []
    fenced = False
    current: Command | None = None     # the last "$ " command of the block, collecting its output
    block = None                       # the line where the current code block began
    i = 0
    while i < len(lines):
        raw = lines[i]
        if raw.lstrip().startswith("```"):
            fenced = not fenced
            current = None
            block = first_line + i if fenced else None
            i += 1
            continue
        code = fenced or raw.startswith("    ")
        if not raw.strip():
            current = None  # a blank line ends a quoted output, not the block
            i += 1
            continue
        if not code:
            current = block = None
            i += 1
            continue
        block = block or first_line + i
        body = raw.strip()
        if PREFIX.match(body):
            number = first_line + i
            joined = body
            while (joined.endswith("\\") or _open_quote(joined)) and i + 1 < len(lines):
                i += 1
                joined = (joined[:-1].rstrip() if joined.endswith("\\") else joined) + " " + lines[i].strip()
            prompt = joined.startswith("$ ")
            joined = _strip_comment(joined[2:] if prompt else joined)
            for part in _commands_in_line(joined):
                found.append(Command(f"{source}:{number}", part, group=f"{source}:{block}"))
            current = found[-1] if prompt else None
        elif current is not None:
            current.output.append(body)
        i += 1
    tick = "``" if double_ticks else "`"
    span = re.compile(rf"(?<!`){tick}((?:ipir-mujoco|python3?) [^`]+?){tick}(?!`)")
    for match in span.finditer(text):
        number = first_line + text.count("\n", 0, match.start())
        paragraph = first_line + text.count("\n", 0, max(text.rfind("\n\n", 0, match.start()), 0))
        command = " ".join(match.group(1).replace("\\|", "|").split())
        line = text[text.rfind("\n", 0, match.start()) + 1:match.start()]
        for part in _commands_in_line(command):
            found.append(Command(f"{source}:{number}", part, inline=True, group=f"{source}:{paragraph}p",
                                 heading=line.startswith("#")))
    return found


def sources() -> list[Path]:
    """Every file whose text the user reads: pages, the route files' headers, modules' docstrings."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), ROOT / "mjcf" / "README.md"]
    modules = [*sorted((ROOT / "bench").glob("*.py")), *sorted((ROOT / "ipir_mujoco").rglob("*.py")),
               *sorted((ROOT / "analytic").glob("*.py"))]
    return [*pages, *sorted((ROOT / "mjcf").glob("*.toml")), *modules]


def extract(path: Path) -> list[Command]:
    """The commands in one file, in order."""
    name = str(path.relative_to(ROOT))
    text = path.read_text()
    if path.suffix == ".md":
        return parse(text, name)
    if path.suffix == ".toml":
        header = []
        for line in text.splitlines():
            if not line.startswith("#"):
                break
            header.append(line[2:] if line.startswith("# ") else line[1:])
        return parse("\n".join(header), name)
    docstring = ast.get_docstring(ast.parse(text), clean=True)
    if not docstring:
        return []
    start = text.index(docstring.splitlines()[0]) if docstring.splitlines()[0] in text else 0
    return parse(docstring, name, text.count("\n", 0, start) + 1, double_ticks=True)


def all_commands() -> dict[str, list[Command]]:
    """group (code block or paragraph) -> its commands, in order. A command shown before, with the same
    quoted output, is kept once (where first shown) unless its group has others (which may need it: a
    sweep's folder that the next command reads)."""
    groups: dict[str, list[Command]] = {}
    for path in sources():
        commands = extract(path)
        # inline commands of a paragraph depend on each other only through a file ('> before.txt' then
        # '| diff before.txt -'); otherwise each is a group of its own
        chained = {c.group for c in commands if c.inline and re.search(r"[>|]", c.text)}
        for command in commands:
            if command.inline and command.group not in chained:
                command.group = command.source + "i"
            groups.setdefault(command.group, []).append(command)
    seen, out = set(), {}
    for name, commands in groups.items():
        kept = []
        for command in commands:
            key = (command.text, tuple(command.output))
            if key not in seen or len(commands) > 1:
                kept.append(command)
            seen.add(key)
        if kept:
            out[name] = kept
    return out


def options_shown(synopsis: str) -> list[str]:
    """The long options a synopsis shows ('--out', '--set', ...)."""
    return sorted(set(re.findall(r"(?<![\w-])--[a-z][\w-]*", synopsis)))


def program(command: str) -> list[str]:
    """The program part of a command, for its --help: ['ipir-mujoco', 'sweep'], ['python', 'bench/x.py'],
    ['python', '-m', 'ipir_mujoco.view']."""
    words = shlex.split(command.replace("[", " [").split("[", 1)[0].replace("(", " "))
    if words[0] == "ipir-mujoco":
        return words[:2] if len(words) > 1 and re.fullmatch(r"[a-z][a-z-]*", words[1]) else words[:1]
    if len(words) > 2 and words[1] == "-m":
        return words[:3] if not words[2].startswith("-") else words[:2]
    return words[:2]


# a documented command whose output other tests read: (as documented, as the test runs it, the module that reads
# it). It runs once in a pytest process (tests/conftest.py's shared_command), and the documented command's test
# runs with that module (conftest.scope_of): one `validate --quick` for the README's first command and the
# report's tests, not two.
SHARED_RUNS = (("ipir-mujoco validate", "ipir-mujoco validate --quick", "tests/test_validate.py"),)

# counts of draws or runs a command's options set, capped by the test: (option, largest value run)
CAPS = (("--samples", 16), ("--budget", 16), ("--mujoco-samples", 3))
# where a command's --help offers these and the command leaves them at their defaults: (option, value run)
DEFAULT_CAPS = (("--samples", 16), ("--budget", 8))
# a video's frame rate (render: 25 by default, the frames cost most of its time): a fifth of the frames
VIDEO_FPS = ("--fps", 5)
# the points of a grid (--vary NAME=LO:HI:N) in a block that quotes no output: enough for a line and its ends
GRID_CAP = 8


def shortened(command: str, help_of, grids: bool = True) -> tuple[str, str]:
    """(the command as the test runs it, how it was shortened or ''): benchmarks get --smoke, a command
    whose program takes --quick (``help_of(program(command))`` lists it) gets it, a count of random draws
    or runs (``--samples N``, ``--budget N``, ``--mujoco-samples M``) is capped (:data:`CAPS`), where the
    program offers ``--samples`` or ``--budget`` and the command leaves them at their defaults they are set
    small (:data:`DEFAULT_CAPS`), a video is made at a low frame rate (:data:`VIDEO_FPS`), and with ``grids``
    (a block that quotes no output: no printed figure depends on the grid) a grid's count of points
    (``--vary NAME=LO:HI:N``) is capped (:data:`GRID_CAP`)."""
    if re.search(r"python3? bench/\w+\.py", command):
        if "--smoke" in command.split():
            return command, "--smoke"
        new = re.sub(r"(python3? bench/\w+\.py(?:\s+(?![|>&])\S+)*)", r"\1 --smoke", command)
        return new, "--smoke"
    how = []
    if grids and command.startswith("ipir-mujoco "):
        def cap(match):
            if int(match.group(3)) <= GRID_CAP:
                return match.group(0)
            how.append(f"{match.group(1)} {GRID_CAP} points")
            return f"{match.group(1)}={match.group(2)}:{GRID_CAP}"
        command = re.sub(r"(?<=--vary )([\w-]+)=([-\d.e]+:[-\d.e]+):(\d+)\b", cap, command)
    for option, cap in CAPS:
        match = re.search(rf"{option} (\d+)\b", command)
        if match and int(match.group(1)) > cap and command.startswith("ipir-mujoco "):
            command = command[:match.start(1)] + str(cap) + command[match.end(1):]
            how.append(f"{option} {cap}")
    if re.search(r"[|>&]", command) or not command.startswith(("ipir-mujoco ", "python -m ")):
        return command, ", ".join(how)
    text = help_of(tuple(program(command)))
    if "--quick" not in command.split() and "--quick" in text:
        command += " --quick"
        how.append("--quick")
    for option, value in DEFAULT_CAPS:
        if re.search(rf"(?<![\w-]){option} N\b", text) and option not in command.split():  # a count, not a file
            command += f" {option} {value}"
            how.append(f"{option} {value}")
    if re.search(rf"(?<![\w-]){VIDEO_FPS[0]}\b", text) and VIDEO_FPS[0] not in command.split():
        command += f" {VIDEO_FPS[0]} {VIDEO_FPS[1]}"
        how.append(f"{VIDEO_FPS[0]} {VIDEO_FPS[1]}")
    return command, ", ".join(how)


INPUTS = re.compile(r"(?<!--out )(?<!--save-mjcf )(?<![\w/.-])((?:[\w.-]+/)*[\w.-]+\.(?:csv|toml|xml|json))\b")


def missing_inputs(command: str, folder) -> list[str]:
    """The files a command reads (a .csv, .toml, .xml or .json argument, not one it writes: --out,
    --save-mjcf, a redirection) that are not in ``folder``: an example's own data the docs do not make."""
    from pathlib import Path

    head = re.split(r"\s[>|]", command)[0]
    if head.startswith("python -c"):
        return []
    return [name for name in INPUTS.findall(head) if not (Path(folder) / name).exists()]


WALL = re.compile(r"\(?[\d.]+ (?:ms|s) wall\)?")


def normal(line: str) -> str:
    """A line of output compared without its spacing and wall times."""
    return " ".join(WALL.sub("(wall)", line).split())


def missing_output(quoted: list[str], printed: str) -> list[str]:
    """The quoted lines the printed output does not hold, in order ('...' lines skipped)."""
    lines = [normal(line) for line in printed.splitlines()]
    missing, at = [], 0
    for line in quoted:
        want = normal(line)
        if want in ("...", ""):
            continue
        try:
            at = lines.index(want, at) + 1
        except ValueError:
            missing.append(line)
    return missing
