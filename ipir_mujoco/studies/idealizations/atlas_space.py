"""The atlas's idealizations and metrics: which two models measure each idealization's cost, and how.

Each idealization of the paper's model is measured by a *pair* of runs of one design that differ in that one
idealization only: the model that keeps it (``idealized``) and the one that removes it (``real``), both rungs
of the model ladder (:mod:`.ladder`), run through :func:`ipir_mujoco.registry.run`. Its cost on a metric is
the signed relative error the idealization makes, (idealized - real) / |real| (as the L/r line of the
validation report, :mod:`.lr_study`); the atlas asks where |cost| stays below a threshold.

======================  ===========================================  ===========================================
idealization            equations (cheap: dense samples)             MuJoCo (seconds a run: ``--budget``)
======================  ===========================================  ===========================================
first-order-kinematics  paper model vs exact geometry (massless rod)  -- (MuJoCo always models the real linkage)
massless-rod            exact geometry, massless vs the design's rod  --
locking-clutches        paper's rule vs one-way clutches (with rod)   MuJoCo's locks vs its ratchet
unlimited-grip          one-way clutches, unlimited vs finite grip    MuJoCo's ratchet, unlimited vs finite grip
constant-press          --                                            slides (constant press) vs the round pipe
======================  ===========================================  ===========================================

The first three are measured on unlimited grip whatever ``mu_wall`` is (the paper's rule locks a module
whatever the load, in the equations as in MuJoCo's locks: they have no grip to make finite), so that each
isolates its own idealization; ``unlimited-grip`` needs a finite ``mu_wall`` (given, or varied);
``massless-rod`` a rod with mass; ``constant-press`` MuJoCo runs (a budget). ``constant-press`` compares the
slides, on which the wall press is the constant ``F_n1``, ``F_n2``, with the wheeled model in a round pipe,
whose press comes from its legs' springs; its wheeled runs keep the validation ladder's accuracy setting
(``warn``: :data:`.ladder.CONTACT`).

Metrics: under the paper's constant torque, a run of ``t_end`` from rest (:data:`TORQUE_METRICS`); under the
motor or the servo, a run to its periodic steady state (:data:`MOTOR_METRICS`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from ipir_mujoco import registry
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.limits import study_dt_out
from ipir_mujoco.core.params import RobotParams

if TYPE_CHECKING:  # the atlas command's parser reads this module's defaults without numpy
    from ipir_mujoco.core.results import RunResult

from ..figure_errors import figure_error
from ..validation.ladder import VALIDATION_LADDER, Rung

RUNGS = {rung.name: rung for rung in VALIDATION_LADDER}
# the atlas's defaults, here rather than in atlas.py so that the command line's help reads them without loading
# the surrogate's scipy (half a second of every command's start)
DEFAULT_BUDGET = 100  # MuJoCo runs (2 per design)
DEFAULT_SAMPLES = 64  # Saltelli base samples of the equations: 64 (d + 2) designs
DEFAULT_TOLERANCE = 0.02  # share of the box left undecided at which MuJoCo's exploration stops
ANALYTIC_WALL_BUDGET_S = 120.0  # s: an analytic run's wall-time budget (they take milliseconds to a second)

# metric: (in words, unit)
TORQUE_METRICS = {
    "revolutions": ("crank revolutions", "rev"),
    "travel_m": ("travel of the robot (mean of the modules)", "m"),
    "x1_final": ("travel of module 1 (rear)", "m"),
    "x2_final": ("travel of module 2 (front)", "m"),
    "v1_max": ("peak speed of module 1", "m/s"),
    "v2_max": ("peak speed of module 2", "m/s"),
}
MOTOR_METRICS = {
    "steady_speed_m_s": ("steady speed", "m/s"),
    "energy_per_metre_j_m": ("energy per metre", "J/m"),
    "distance_per_rev_m": ("distance per crank revolution", "m"),
    "efficiency": ("efficiency", "-"),
    "t_steady_s": ("time to steady state", "s"),
}
METRIC_WORDS = {**TORQUE_METRICS, **MOTOR_METRICS}
DEFAULT_METRICS = {False: ("revolutions", "travel_m"), True: ("steady_speed_m_s", "energy_per_metre_j_m")}


@dataclass(frozen=True)
class Side:
    """One model of a pair: a rung of the ladder, on unlimited grip or on the design's grip."""

    rung: str  # a name of RUNGS
    unlimited_grip: bool = False

    def params(self, params: RobotParams) -> RobotParams:
        p = RUNGS[self.rung].params(params)
        if not self.unlimited_grip or p.mu_wall is None:
            return p
        # on unlimited grip the press holds nothing (the slides' grip is mu_wall F_n): its default, which every
        # engine takes with unlimited grip
        default = RobotParams()
        return p.replace(mu_wall=None, F_n1=default.F_n1, F_n2=default.F_n2)

    @property
    def variant(self) -> str:
        return RUNGS[self.rung].variant


@dataclass(frozen=True)
class Pair:
    idealized: Side
    real: Side

    @property
    def is_mujoco(self) -> bool:
        return registry.variant(self.real.variant).is_mujoco


@dataclass(frozen=True)
class Idealization:
    name: str
    words: str  # what the paper assumes, in words
    equations: Pair | None  # measured by the analytic engines
    mujoco: Pair | None  # measured by MuJoCo

    @property
    def fidelities(self) -> tuple[str, ...]:
        return tuple(f for f, pair in (("equations", self.equations), ("mujoco", self.mujoco)) if pair is not None)

    def pair(self, fidelity: str) -> Pair:
        return self.equations if fidelity == "equations" else self.mujoco


IDEALIZATIONS = {i.name: i for i in (
    Idealization("first-order-kinematics", "first-order kinematics (L >> r)",
                 Pair(Side("paper model", True), Side("exact geometry", True)), None),
    Idealization("massless-rod", "a massless connecting rod",
                 Pair(Side("exact geometry", True), Side("with rod mass", True)), None),
    Idealization("locking-clutches", "clutches that lock both ways by the sign of S_dot (the paper's rule)",
                 Pair(Side("with rod mass", True), Side("one-way clutches", True)),
                 Pair(Side("MuJoCo, paper's rule", True), Side("MuJoCo ratchet", True))),
    Idealization("unlimited-grip", "wheels that never skid (unlimited grip)",
                 Pair(Side("one-way clutches", True), Side("one-way clutches")),
                 Pair(Side("MuJoCo ratchet", True), Side("MuJoCo ratchet"))),
    Idealization("constant-press", "a constant wall press on slides (no wheels, no round pipe)",
                 None, Pair(Side("MuJoCo ratchet"), Side("wheels in contact"))),
)}
NAMES = tuple(IDEALIZATIONS)


def allowed(base: RobotParams, varied: set[str], budget: int) -> dict[str, str]:
    """{idealization: why it is not allowed} for the options given (the rest are allowed)."""
    refused = {}
    if base.rod_mass == 0 and "rod_mass" not in varied:
        refused["massless-rod"] = "rod_mass is 0 (the rod is massless already); set or vary rod_mass > 0"
    if base.mu_wall is None and "mu_wall" not in varied:
        refused["unlimited-grip"] = ("mu_wall is unlimited; give a finite one (--set mu_wall=0.5, with F_n1, F_n2) "
                                     "or vary it")
    if budget == 0:
        refused["constant-press"] = "it is measured in MuJoCo only; give --budget > 0"
    return refused


def metric_value(metric: str, run: RunResult) -> float | None:
    if metric == "travel_m":
        from ipir_mujoco.core.cycles import travel

        x = travel(run.series)
        return float(x[-1] - x[0])
    value = run.summary.get(metric)
    return None if value is None else float(value)


def signed_cost(idealized, real) -> float | None:
    """(idealized - real) / |real|, None where either is missing or real is 0."""
    if idealized is None or real is None or real == 0:
        return None
    return (idealized - real) / abs(real)


def run_side(side: Side, params: RobotParams, t_end: float, until_steady: bool) -> RunResult:
    rung: Rung = RUNGS[side.rung]
    mujoco = registry.variant(rung.variant).is_mujoco
    options = {"accuracy": rung.accuracy} if mujoco else {"wall_budget_s": ANALYTIC_WALL_BUDGET_S}
    return registry.run(rung.variant, side.params(params), t_end, dt_out=study_dt_out(t_end, min(1e-3, t_end)),
                        until_steady=until_steady, **options)


def measure(pair: Pair, params: RobotParams, metrics: tuple[str, ...], t_end: float, until_steady: bool) -> dict:
    """Both runs of ``pair`` on ``params``: {"idealized": {metric: value}, "real": {...}, "cost": {...},
    "note": stall reasons, "error": why a run gave nothing ("" if none)}."""
    out: dict = {"idealized": {}, "real": {}, "cost": {}, "cost_error": {}, "note": "", "error": ""}
    notes, bars = [], {}
    for key, side in (("idealized", pair.idealized), ("real", pair.real)):
        try:
            run = run_side(side, params, t_end, until_steady)
        except (ParameterError, SimulationError) as exc:
            out["error"] = f"{side.variant}: {' '.join(str(exc).split())}"
            break
        except Exception as exc:  # noqa: BLE001 (one design's surprise is recorded; the atlas goes on)
            out["error"] = f"{side.variant}: internal error: {type(exc).__name__}: {' '.join(str(exc).split())}"
            break
        if run.stall:
            notes.append(f"{side.variant}: stalled: {run.stall}")
        grip = run.summary.get("grip1_n")
        if grip is not None:  # the round pipe's grip as MuJoCo has it, beside the constant press's mu_wall F_n
            p = run.params
            notes.append(f"{side.variant}: grip {grip:.4g} / {run.summary['grip2_n']:.4g} N (mu_wall x measured "
                         f"press) against mu_wall F_n {p.mu_wall * p.F_n1:.4g} / {p.mu_wall * p.F_n2:.4g} N")
        elif until_steady and not run.summary.get("steady"):  # its steady figures are empty: say why
            notes.append(f"{side.variant}: not steady by {t_end:g} s")
        out[key] = {m: metric_value(m, run) for m in metrics}
        bars[key] = {m: figure_error(run.summary, m) for m in metrics}  # MuJoCo's figures on finite grip: their bars
    out["note"] = " | ".join(notes)
    if not out["error"]:
        out["cost"] = {m: signed_cost(out["idealized"][m], out["real"][m]) for m in metrics}
        out["cost_error"] = {m: cost_error(out["idealized"][m], out["real"][m], bars["idealized"][m], bars["real"][m])
                             for m in metrics}
    return out


def cost_error(idealized, real, idealized_error, real_error) -> float | None:
    """The error bar of :func:`signed_cost` from its runs' figures' error bars (first order: (e_i + |i / r| e_r) /
    |r|); None where neither run states one or the cost is missing."""
    if (idealized_error is None and real_error is None) or idealized is None or real is None or real == 0:
        return None
    return ((idealized_error or 0.0) + abs(idealized / real) * (real_error or 0.0)) / abs(real)
