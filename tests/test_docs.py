"""The documentation says what the code does: every option, summary key and parameter is in docs/cli.md."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

from ipir_mujoco.analytic import RobotParams, simulate
from ipir_mujoco.core.params import describe_parameters
from ipir_mujoco.cli import TOOLS, build_parser
from ipir_mujoco.cli.params import format_table
from ipir_mujoco.studies import declared

DOCS = Path(__file__).resolve().parent.parent / "docs"
CLI = (DOCS / "cli.md").read_text()


def _sections() -> dict[str, str]:
    """docs/cli.md's text under each '## `ipir-mujoco NAME`' heading."""
    parts = re.split(r"^## ", CLI, flags=re.MULTILINE)
    return {m.group(1): part for part in parts if (m := re.match(r"`ipir-mujoco ([\w-]+)`", part))}


def test_every_subcommand_and_option_is_documented():
    parser = build_parser()
    subparsers = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    sections = _sections()
    # one module per tool (cli/kinetostatics.py is `kinetostatics`) and one declaration per study with a command
    assert set(subparsers.choices) == set(sections) == {c.__name__.rsplit(".", 1)[-1].replace("_", "-")
                                                         for c in TOOLS} | {s.name for s in declared() if s.command}
    shared = CLI.split("## Options every model command shares")[1].split("\n## ")[0]
    for name, sub in subparsers.choices.items():
        for action in sub._actions:
            for option in action.option_strings:
                if option in ("-h", "--help"):
                    continue
                assert option in sections[name] or option in shared, f"{name} {option} is not in docs/cli.md"


def test_every_summary_key_is_documented():
    summary = simulate(RobotParams(), "approx", "kinematic", 0.1).summary
    for key in list(summary) + list(summary["energy"]):
        assert re.search(rf"\b{key}\b", CLI), key


def test_params_listing_fits_100_columns_and_says_everything():
    rows = describe_parameters()
    text = format_table(rows)
    assert max(len(line) for line in text.splitlines()) <= 100
    flat = " ".join(text.split())
    for row in rows:
        for field in (row["name"], row["units"], row["default_text"], row["meaning"], row["allowed"]):
            assert " ".join(field.split()) in flat, field
    # docs/cli.md shows the listing as the command prints it
    assert "\n".join("    " + line if line else "" for line in text.splitlines()) in CLI


def test_docs_link_only_to_files_that_exist():
    for page in DOCS.glob("*.md"):
        for target in re.findall(r"\]\(([^)#]+)\)", page.read_text()):
            if not target.startswith("http"):
                assert (page.parent / target).exists(), f"{page.name} links to {target}"


def test_every_model_variant_and_alias_is_documented():
    from ipir_mujoco import registry

    section = CLI.split("## Model variants: one name per model")[1].split("\n## ")[0]
    for name in (*registry.NAMES, *registry.ALIASES):
        assert f"`{name}`" in section, name


def test_the_docs_import_robotparams_one_way():
    """README and docs/ import the parameter set as the package's public name, one way (not from
    ipir_mujoco.analytic here and ipir_mujoco.core.params there)."""
    root = Path(__file__).resolve().parent.parent
    imports = [line.strip() for page in [root / "README.md", *sorted((root / "docs").glob("*.md"))]
               for line in page.read_text().splitlines()
               if "import" in line and "RobotParams" in line and line.strip().startswith(("from ", "import "))]
    assert imports and all(line.startswith("from ipir_mujoco import ") for line in imports), imports
