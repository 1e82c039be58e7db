"""The energy terms of a run, one table for every engine: a new effect's energy is a row here.

Each term is a series column (cumulative from 0 at the first sample, or a state whose change counts), the key
under which a run's energy audit (``RunResult.energy``) reports its change [J], and its role in the balance

    input = kinetic gained + stored gained + dissipated + residual

``input``: the drive's work; ``kinetic``: the kinetic energy; ``stored``: energy held and given back
(gravity's potential, the compliant clutches' springs); ``dissipated``: work lost (against the resistances,
in the clutches' dampers, by skidding wheels). A run has the terms whose columns it writes (:func:`terms_of`).

Read by: every analytic model's audit (:func:`audit`), the MuJoCo engine's audit and its per-sample accuracy
monitor (:func:`by_role`, :func:`residual`), the per-revolution audit (:class:`.cycles.Cycle`, keyed by the
terms' audit keys) and the command line's energy line (``ipir-mujoco simulate``, the terms' ``name``). A new
effect's energy is one row here (its column written by the engines); ``tests/test_energy_table.py`` holds that a
row reaches each of them.
"""

from __future__ import annotations

from dataclasses import dataclass

INPUT, KINETIC, STORED, DISSIPATED = "input", "kinetic", "stored", "dissipated"


@dataclass(frozen=True)
class EnergyTerm:
    """One energy term.

    Attributes
    ----------
    name : str
        Its name in words (the command line's energy line).
    column : str
        The series column [J] it is read from.
    audit_key : str
        Its key in ``RunResult.energy`` [J]: the column's change over the run.
    role : str
        INPUT, KINETIC, STORED or DISSIPATED (module docstring).
    """

    name: str
    column: str
    audit_key: str
    role: str


ENERGY_TERMS = (  # within a role, the order in which its terms are summed (by_role)
    EnergyTerm("motor", "motor_work", "motor_work_j", INPUT),
    EnergyTerm("kinetic", "kinetic", "kinetic_j", KINETIC),
    EnergyTerm("friction", "friction_work", "friction_j", DISSIPATED),
    EnergyTerm("potential", "potential", "potential_j", STORED),
    EnergyTerm("clutch springs", "clutch_spring_energy", "clutch_spring_j", STORED),
    EnergyTerm("clutch dampers", "clutch_damper_work", "clutch_damper_j", DISSIPATED),
    EnergyTerm("skid", "skid_work", "skid_j", DISSIPATED),
)
ENERGY_COLUMNS = tuple(term.column for term in ENERGY_TERMS)
# terms only runs along a route have, after the table's (the wheels' scrub in a bend: the analytic route model
# books it, zero until its closed form is in, analytic/route_kernels.scrub_force); MuJoCo's per-sample monitor
# records the table above, every engine's run writes its columns, a route run these too
ROUTE_TERMS = (EnergyTerm("scrub", "scrub_work", "scrub_j", DISSIPATED),)
RESIDUAL_KEY = "residual_j"  # the audit's residual: input - kinetic - stored - dissipated [J]


def all_terms() -> tuple[EnergyTerm, ...]:
    """Every term a run may have: the table's, then a route run's (read when called: a test may extend the table)."""
    return (*ENERGY_TERMS, *ROUTE_TERMS)


def terms_of(columns) -> tuple[EnergyTerm, ...]:
    """The terms of a run whose series has ``columns`` (any container of names), in the table's order."""
    return tuple(term for term in all_terms() if term.column in columns)


def changes(series: dict, terms=None) -> dict[EnergyTerm, float]:
    """Each term's change [J] over a run, first to last sample of its column in ``series`` (columns of shape
    (n,)); ``terms``: the run's (default: those whose columns ``series`` has)."""
    terms = terms_of(series) if terms is None else terms
    return {term: series[term.column][-1] - series[term.column][0] for term in terms}


def by_role(change: dict) -> dict[str, float]:
    """{role: the sum of its terms' changes, added in the table's order (0.0 where it has none)} of ``change``
    ({EnergyTerm: J}); residual = input - dissipated - kinetic - stored."""
    out = {}
    for role in (INPUT, KINETIC, STORED, DISSIPATED):
        values = [change[t] for t in all_terms() if t in change and t.role == role]
        total = values[0] if values else 0.0
        for value in values[1:]:
            total = total + value
        out[role] = total
    return out


def audit_keys(change: dict) -> dict[str, float]:
    """``change`` ({EnergyTerm: J}) under the terms' audit keys, as floats."""
    return {term.audit_key: float(value) for term, value in change.items()}


def residual(total: dict):
    """The balance's residual, input - dissipated - kinetic - stored [J], of ``total`` ({role: J}, floats or arrays
    of one shape): the one order every audit subtracts in (so that two audits of one run agree to the bit)."""
    return total[INPUT] - total[DISSIPATED] - total[KINETIC] - total[STORED]


def audit(series: dict, terms=None) -> dict[str, float]:
    """A run's energy audit ({audit key: J}, ``RunResult.energy``): each term's change over the run (the terms whose
    columns ``series`` has, or ``terms``) and the residual (:func:`residual`) under :data:`RESIDUAL_KEY`."""
    change = changes(series, terms)
    return {**audit_keys(change), RESIDUAL_KEY: float(residual(by_role(change)))}
