"""Test-suite settings.

Property-based tests run derandomized by default, so CI is repeatable: the
same examples every run. To explore new random examples (as done when the
one-way-clutch solver was developed), run with HYPOTHESIS_PROFILE=explore.
"""

import os
import sys
from pathlib import Path

import pytest
from hypothesis import settings

sys.path.insert(0, str(Path(__file__).resolve().parent))
from docs_commands import SHARED_RUNS  # noqa: E402

settings.register_profile("repeatable", derandomize=True, deadline=None)
settings.register_profile("explore", derandomize=False, deadline=None, max_examples=300)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


def pytest_configure(config):
    """A suite started in the background by a shell without job control (``(pytest &)``, a script's ``pytest &``)
    inherits SIGINT ignored, and so would every command line its tests start: the tests that send Ctrl-C, to
    this process or to a command they started, get Python's usual handler back, as a terminal gives it."""
    import signal

    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_sessionstart(session):
    """Compile the analytic kernels (numba, where installed) before any test: the first compilation on a
    machine takes about 15-40 s and the command line then says so on stderr, which the command-line tests
    read; every later process loads the cached code. The compile's heartbeat (analytic/accel.py), a thread that
    says "still compiling" / "kernels compiled" every HEARTBEAT_S while numba works, is put to sleep for good
    here: its lines would land in whichever test's stderr runs when it wakes (a cold cache in CI: "kernels
    compiled (27 s)" inside tests/test_clutch_study.py). tests/test_fast_kernels.py tests it with its own period."""
    from ipir_mujoco.analytic import RobotParams, accel, simulate

    period = accel.HEARTBEAT_S
    accel.HEARTBEAT_S = 1e9  # read once as the thread goes to sleep: a thread started now never wakes to log
    try:
        accel.accelerate()  # compile now (or load the cache) whatever the runs below spend
        _warm_up(RobotParams, simulate)
    finally:
        accel.HEARTBEAT_S = period


def _warm_up(RobotParams, simulate) -> None:
    """Short runs of each analytic engine: numba compiles each kernel at its first call."""
    for geometry, clutch, params in (("approx", "kinematic", RobotParams()), ("exact", "kinematic", RobotParams()),
                                     ("exact", "unilateral", RobotParams()),
                                     ("exact", "unilateral", RobotParams(clutch_stiffness=1e5))):
        simulate(params, geometry, clutch, 0.02, dt_out=1e-3)



# ---------------------------------------------------------------------------------------------------------------
# Running in parallel: pyproject.toml's addopts ask for '-n auto --dist loadscope' (pytest-xdist, in the test extra:
# one worker per core). Each test module goes to one worker whole, so a run that several of its tests read
# (module-scoped fixtures) is made once; the documented commands are split by their code block (the first word of
# the test's id), whose commands run in order in one folder. Groups holding slow tests are handed out first, so
# that no long group starts last. Without pytest-xdist the same options are accepted and the suite runs in this
# one process, in its usual order.

SPLIT_BY_FIRST_WORD_OF_ID = ("tests/test_docs_commands.py::test_documented_command[",)


def scope_of(nodeid: str) -> str:
    """The group a test runs in: its module, or for a test listed above, the first word of its id; a documented
    command whose run other tests read (docs_commands.SHARED_RUNS) goes with their module."""
    for prefix in SPLIT_BY_FIRST_WORD_OF_ID:
        if nodeid.startswith(prefix):
            words = nodeid[len(prefix):-1].split(" ", 2)
            for documented, _ran, reader in SHARED_RUNS:
                if words[-1] == documented:
                    return reader
            return prefix + words[0]
    return nodeid.split("::", 1)[0]


@pytest.fixture(scope="session")
def shared_command(tmp_path_factory):
    """``shared_command(text)``: ``text`` run once by bash in a folder of its own in this pytest process, as a
    user types it (cli_run.run_shell); the CompletedProcess with ``.folder`` where it ran. For the runs several
    tests read (docs_commands.SHARED_RUNS)."""
    from cli_run import run_shell

    done = {}

    def run(text: str):
        if text not in done:
            folder = tmp_path_factory.mktemp("shared")
            done[text] = run_shell(text, folder)
            done[text].folder = folder
        return done[text]
    return run


def pytest_addoption(parser, pluginmanager):
    if not pluginmanager.hasplugin("xdist"):
        group = parser.getgroup("xdist", "pytest-xdist is not installed: the tests run in this one process")
        # _addoption: a lowercase short option is pytest's own (pytest-xdist declares its -n the same way)
        group._addoption("-n", "--numprocesses", dest="numprocesses", default=None,
                        help="accepted and ignored (pip install pytest-xdist to run tests in parallel)")
        group.addoption("--dist", dest="dist", default="no", help="accepted and ignored (see -n)")


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """xdist's scheduling by scope with :func:`scope_of`'s groups, in the order the workers collected them."""
    from xdist.scheduler import LoadScopeScheduling

    class Scheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return scope_of(nodeid)

    config.option.loadscopereorder = False  # keep the order below (xdist would sort the groups by their size)
    return Scheduling(config, log)


def pytest_collection_modifyitems(config, items):
    """In an xdist worker: the groups that hold a slow test first (each group's tests keep their order)."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return
    units: dict[str, list] = {}
    for item in items:
        units.setdefault(scope_of(item.nodeid), []).append(item)
    ordered = sorted(units.values(), key=lambda unit: not any(i.get_closest_marker("slow") for i in unit))
    items[:] = [item for unit in ordered for item in unit]
