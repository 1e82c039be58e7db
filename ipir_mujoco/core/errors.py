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
