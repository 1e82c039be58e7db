"""Options of the commands that run many designs (sweep, optimize, sensitivity): the Dask scheduler, and the
run options optimize and sensitivity share."""

from __future__ import annotations

import argparse
from contextlib import contextmanager

from ipir_mujoco.core.errors import ParameterError

from .sweeps.sweep_space import T_END_STEADY

SCHEMES = ("tcp", "tls", "ws", "wss")  # Dask's network transports
CONNECT_TIMEOUT_S = 5.0  # s: a scheduler on the network answers in milliseconds; a wrong address is not waited on


def scheduler_address(address: str) -> tuple[str, str, int]:
    """(scheme, host, port) of a Dask scheduler address ``[SCHEME://]HOST:PORT``, or a one-line
    ParameterError naming it and the allowed form."""
    allowed = (f"allowed: SCHEME://HOST:PORT with SCHEME one of {', '.join(SCHEMES)} (e.g. tcp://host:8786), "
               "or the inproc:// address of a cluster in this process")
    scheme, _, rest = address.strip().rpartition("://")
    scheme = scheme or "tcp"
    if scheme == "inproc" and rest:  # a LocalCluster(processes=False) of this process: no socket to probe
        return scheme, rest, 0
    host, _, port = rest.rpartition(":")
    host = host.strip("[]")
    if scheme not in SCHEMES or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ParameterError(f"--scheduler {address!r} is not a scheduler address; {allowed}")
    return scheme, host, int(port)


def connect_scheduler(address: str):
    """A Dask ``Client`` of the scheduler at ``address``; an address that is malformed, or where nothing
    answers within CONNECT_TIMEOUT_S, is a one-line ParameterError naming it (tried with a plain socket
    first, so that the answer comes in seconds)."""
    import socket

    scheme, host, port = scheduler_address(address)
    try:
        from distributed import Client
    except ImportError:
        raise ParameterError("--scheduler needs Dask: pip install 'ipir-mujoco[dask]'") from None
    try:
        if scheme != "inproc":
            socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S).close()
    except OSError as exc:
        raise ParameterError(f"--scheduler {address!r} cannot be reached ({exc.strerror or exc or 'timed out'}); "
                             "allowed: the address of a running Dask scheduler") from None
    try:
        return Client(address if "://" in address else f"tcp://{address}", timeout=f"{CONNECT_TIMEOUT_S:g}s")
    except Exception as exc:  # noqa: BLE001 (whatever Dask raises: a handshake that is not a scheduler's)
        raise ParameterError(f"--scheduler {address!r} did not answer as a Dask scheduler "
                             f"({type(exc).__name__}: {' '.join(str(exc).split())[:200]})") from None


def add_scheduler_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run on a Dask distributed scheduler (needs the 'dask' extra), e.g. tcp://host:8786")


@contextmanager
def scheduler_executor(address: str | None):
    """The executor of the Dask scheduler at ``address`` (:func:`connect_scheduler`), or None without one (the
    local pool); the client is closed on the way out, whatever happens."""
    client = connect_scheduler(address) if address is not None else None
    try:
        yield client.get_executor() if client is not None else None
    finally:
        if client is not None:
            client.close()


def add_design_run_options(parser: argparse.ArgumentParser) -> None:
    """--seed, --t-end, --until-steady (before the model options), as optimize and sensitivity read them."""
    parser.add_argument("--seed", type=int, default=None, help="seed, >= 0 (default 0)")
    parser.add_argument("--t-end", type=float, default=None, metavar="SECONDS",
                        help="simulated time per design (default 1 s; with --until-steady the cap, default 10 s)")
    parser.add_argument("--until-steady", action="store_true", help="run every design to its periodic steady state")


def add_output_options(parser: argparse.ArgumentParser, out: str, what: str) -> None:
    """--out DIR (default ./``out``), --resume, --workers and --scheduler, as optimize and sensitivity read them."""
    parser.add_argument("--out", metavar="DIR", default=out, help=f"results folder (default ./{out})")
    parser.add_argument("--resume", action="store_true", help=f"complete an interrupted {what} in DIR")
    parser.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    add_scheduler_option(parser)


def design_t_end(args: argparse.Namespace) -> float:
    """Simulated time per design [s]: --t-end, else 1 s, or the cap T_END_STEADY with --until-steady."""
    return args.t_end if args.t_end is not None else (T_END_STEADY if args.until_steady else 1.0)
