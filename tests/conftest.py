"""Test-suite settings.

Property-based tests run derandomized by default, so CI is repeatable: the
same examples every run. To explore new random examples (as done when the
one-way-clutch solver was developed), run with HYPOTHESIS_PROFILE=explore.
"""

import math
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


KERNELS_READY = "IPIR_TEST_KERNELS_READY"  # the compile process's ready file, for the workers (tests/kernel_warmup.py)


def pytest_sessionstart(session):
    """The analytic kernels compiled before any test (tests/kernel_warmup.py): here, in one process; under
    pytest-xdist (the controller runs the session's dsession plugin) by a process of its own, started now, while
    the workers start and collect; they wait for it before their first test (:func:`pytest_collection_finish`)."""
    import subprocess
    import tempfile

    if os.environ.get("PYTEST_XDIST_WORKER"):
        if os.environ.get(KERNELS_READY):  # no compiling while the controller's compile runs (a module's run at
            from ipir_mujoco.analytic import accel  # import would start one after LOAD_COST_S of Python)

            session.config._load_cost, accel.LOAD_COST_S = accel.LOAD_COST_S, math.inf
        return
    if not session.config.pluginmanager.has_plugin("dsession"):
        from kernel_warmup import warm_up

        warm_up()
        return
    ready = Path(tempfile.mkdtemp(prefix="ipir-kernels-")) / "ready"
    os.environ[KERNELS_READY] = str(ready)  # the workers, started after this hook, inherit it
    session.config._kernels = subprocess.Popen(  # its stderr: a failed compile says why, as a process would
        [sys.executable, str(Path(__file__).with_name("kernel_warmup.py")), str(ready)], stdout=subprocess.DEVNULL)


def pytest_collection_finish(session):
    """In a pytest-xdist worker: wait for the controller's compile, then load the cached kernels here."""
    if os.environ.get("PYTEST_XDIST_WORKER") and os.environ.get(KERNELS_READY):
        from ipir_mujoco.analytic import accel
        from kernel_warmup import wait_for, warm_up

        wait_for(Path(os.environ[KERNELS_READY]))
        accel.LOAD_COST_S = session.config._load_cost
        warm_up()


def pytest_sessionfinish(session):
    """The controller: the compile process ended (killed if a short session outran it), its folder removed."""
    import shutil

    process = getattr(session.config, "_kernels", None)
    if process is not None:
        if process.poll() is None:
            process.kill()
        process.wait()
        shutil.rmtree(Path(os.environ[KERNELS_READY]).parent, ignore_errors=True)


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
    """``shared_command(text)``: ``text`` run once in a folder of its own for this pytest process, as a user types
    it (cli_run.run_command); the CompletedProcess with ``.folder`` where it ran. For the runs several tests read
    (docs_commands.SHARED_RUNS)."""
    from cli_run import run_command

    done = {}

    def run(text: str):
        if text not in done:
            folder = tmp_path_factory.mktemp("shared")
            done[text] = run_command(text, folder)
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
