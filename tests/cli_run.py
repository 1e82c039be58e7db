"""Running the command line inside a test: its exit status, standard output and standard error."""

from __future__ import annotations

from ipir_mujoco.cli import main


def exit_code(argv) -> int:
    """main()'s exit status, whether it returns it or argparse exits with it."""
    try:
        return main([str(a) for a in argv])
    except SystemExit as exc:
        return exc.code


def run_cli(capsys, *argv):
    """(exit status, stdout, stderr) of ``ipir-mujoco ARGV``, captured by pytest's ``capsys``."""
    code = exit_code(argv)
    out, err = capsys.readouterr()
    return code, out, err
