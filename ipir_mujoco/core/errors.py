"""Exceptions shared by every engine.

Bad input is a :class:`ValueError` (the command line maps it to exit status 2);
a simulation that cannot go on is a :class:`SimulationError` (exit status 1).
"""


class ParameterError(ValueError):
    """A parameter value, name, option or file is not acceptable.

    The message names the offending value and what is allowed, in one line (the command line: exit status 2).

    Parameters
    ----------
    message : str
        The one line.
    """


class ParameterTypeError(ParameterError, TypeError):
    """An argument of the wrong type (``params=None``, a string where a tuple of axes goes): a
    :class:`ParameterError`, so one ``except ValueError`` catches every bad input, and a ``TypeError``, as
    Python users expect of a wrong type."""


class StudyInterrupted(RuntimeError):
    """Ctrl-C (or SIGINT) stopped a study of many designs (sweep, optimize, sensitivity); the message says
    where the results written so far are kept (the command line: exit status 130)."""


class SimulationError(RuntimeError):
    """A simulation failed (solver failure, instability, chattering).

    The message gives the simulated time and the reason, in one line (the command line: exit status 1).

    Parameters
    ----------
    message : str
        The one line.
    """


def refuse_all_failed(errors, what: str = "runs", where: str = "") -> None:
    """A study every one of whose runs failed has failed itself (the command line: exit status 1, not a table of
    errors with exit status 0): a SimulationError naming how many and the first failure. ``errors``: one per
    run, its one-line error or None / '' where it gave a result; ``where``: where the rows are kept, if
    anywhere."""
    errors = list(errors)
    if errors and all(errors):
        kept = f" (the rows are in {where})" if where else ""
        raise SimulationError(f"every one of the {len(errors)} {what} failed; the first: "
                              f"{' '.join(str(errors[0]).split())}{kept}")
