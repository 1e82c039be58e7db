"""The model variants: every model of the robot in one engine by its name, ``ENGINE-MODEL[-RULE]``
(:mod:`ipir_mujoco.registry`'s module docstring says the scheme), and the command line's flags that name one.

:mod:`ipir_mujoco.registry` runs them and gives every name here as its own (``registry.VARIANTS``,
``registry.variant``, ...): numpy-free, so that the command line's parsers read the names (``--help``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .core.errors import ParameterError, ParameterTypeError
from .core.limits import CLUTCH_RULES as RULES  # the clutch rules (--clutch)
from .engine.kinds import KINDS  # the model kinds' declarations (no MuJoCo: engine/kinds/__init__.py)
from .engine.kinds.base import MUJOCO_CLUTCHES  # the MuJoCo clutches a variant names (--mujoco-clutch)

__all__ = ["ALIASES", "ENGINES", "NAMES", "VARIANTS", "Variant", "check_route_flag", "from_flags", "variant"]

ENGINES = ("analytic", "mujoco")  # the two engines; a variant (VARIANTS) is one model in one of them


@dataclass(frozen=True)
class Variant:
    """One model of the robot in one engine (see the module docstring for the names).

    Parameters
    ----------
    name : str
        Its canonical name, ``ENGINE-MODEL[-RULE]``.
    engine : str
        'analytic' or 'mujoco'.
    rule : str
        The clutch rule: 'kinematic' (the paper's) or 'unilateral' (one-way clutches).
    geometry : str
        'approx' or 'exact' (MuJoCo always models the exact linkage).
    clutch : str or None
        MuJoCo's clutch, 'ratchet' or 'lock'; None for the equations.
    label : str
        The variant in words, for figures and reports.
    model : str
        MuJoCo's model of the robot, a model kind's word ('slides', 'wheels'); 'slides' for the equations.
    clutches : str
        Its clutches in words where its model has only those (for a refused flag's message), else ''.
    mechanism : str
        Its clutches' mechanism for a figure's title where MuJoCo's clutch alone does not say it, else ''.
    routes : bool
        Whether it runs along a route of straights and bends (``route=``, ``--route``).
    """

    name: str  # canonical
    engine: str  # 'analytic' | 'mujoco'
    rule: str  # the clutch rule: 'kinematic' (the paper's) | 'unilateral' (one-way clutches)
    geometry: str  # 'approx' | 'exact' (MuJoCo always models the exact linkage)
    clutch: str | None  # MuJoCo's clutch: 'ratchet' | 'lock'; None for the equations
    label: str  # in words, for figures and reports
    model: str = "slides"  # MuJoCo's model of the robot: 'slides' | 'wheels' (the equations: 'slides')
    clutches: str = ""  # its clutches in words, where its model has only those (for a refused flag's message)
    mechanism: str = ""  # its clutches' mechanism for a figure's title, where MuJoCo's clutch alone does not say it
    routes: bool = False  # whether it runs along a route of straights and bends (``route=``, ``--route``)

    @property
    def mechanism_words(self) -> str:
        """The clutches' mechanism in a title's words: MuJoCo's clutch ('ratchet' | 'lock'), or the model's own
        (``mechanism``: the wheels' hub ratchets)."""
        return self.mechanism or self.clutch or ""

    @property
    def is_mujoco(self) -> bool:
        return self.engine == "mujoco"

    def describe(self) -> dict[str, Any]:
        """The variant as a run's JSON records it: name, engine, geometry, clutch rule and MuJoCo's clutch."""
        described = {"variant": self.name, "engine": self.engine, "geometry": self.geometry, "clutch": self.rule,
                     "mujoco_clutch": self.clutch}
        if self.model != "slides":
            described["mujoco_model"] = self.model
        return described


# every variant by its canonical name: {name: Variant}; ``run(name, ...)`` runs one
VARIANTS: dict[str, Variant] = {v.name: v for v in (
    Variant("analytic-approx", "analytic", "kinematic", "approx", None, "paper's model"),
    Variant("analytic-exact", "analytic", "kinematic", "exact", None, "analytic, paper's rule", routes=True),
    Variant("analytic-approx-unilateral", "analytic", "unilateral", "approx", None,
            "analytic first order, one-way clutches"),
    Variant("analytic-unilateral", "analytic", "unilateral", "exact", None, "analytic one-way clutches",
            routes=True),
    # MuJoCo's: each model kind declares its own (engine/kinds/<kind>/__init__.py), in the kinds' order
    *(Variant(engine="mujoco", geometry="exact", model=kind.model, **row) for kind in KINDS.values()
      for row in kind.variants),
)}
ALIASES = {
    "analytic-approx-kinematic": "analytic-approx", "analytic-exact-kinematic": "analytic-exact",
    "analytic-exact-unilateral": "analytic-unilateral", "mujoco-ratchet-unilateral": "mujoco-ratchet",
    "mujoco-lock-kinematic": "mujoco-lock",
}
NAMES = tuple(VARIANTS)
# MuJoCo's models of the robot (``--mujoco-model``): the modules on slides, or on wheels on the pipe walls, ...
MUJOCO_MODELS = tuple(dict.fromkeys(v.model for v in VARIANTS.values() if v.engine == "mujoco"))
# MuJoCo's models that take ``--route``, and every variant that does (the exact equations, MuJoCo's wheels)
ROUTE_MODELS = tuple(dict.fromkeys(v.model for v in VARIANTS.values() if v.routes and v.is_mujoco))
ROUTE_VARIANTS = tuple(v.name for v in VARIANTS.values() if v.routes)
ANALYTIC_ROUTES = tuple(name for name in ROUTE_VARIANTS if not VARIANTS[name].is_mujoco)


def check_route_flag(route: str | None, model: "str | Variant") -> None:
    """ParameterError (one line) for ``--route`` with a variant, or MuJoCo's ``--mujoco-model``, that runs along no
    route: the command line's check before any work (:func:`run` refuses a Python caller's route)."""
    if route is None or isinstance(model, Variant) and model.routes:
        return
    wheels = " or ".join(f"--mujoco-model {m}" for m in ROUTE_MODELS)
    if isinstance(model, Variant) and not model.is_mujoco:
        raise ParameterError(f"--route {route} with {model.name}: the paper's first-order geometry has no linkage to "
                             f"span a bend's chord; allowed: --geometry exact ({', '.join(ANALYTIC_ROUTES)}), or "
                             f"--engine mujoco {wheels}")
    if (model.model if isinstance(model, Variant) else model) not in ROUTE_MODELS:
        raise ParameterError(f"--route {route}: of MuJoCo's models only the {' or '.join(ROUTE_MODELS)} model runs "
                             f"along a route; allowed: --engine mujoco {wheels}, or the equations: --engine analytic "
                             "--geometry exact")


def variant(name: str | Variant) -> Variant:
    """The variant named ``name`` (canonical or an alias).

    Parameters
    ----------
    name : str or Variant
        A name of :data:`NAMES` or an alias (:data:`ALIASES`); a Variant is returned as it is.

    Returns
    -------
    Variant
        The variant.

    Raises
    ------
    ParameterError
        An unknown name, in one line listing the names (a :class:`ParameterTypeError` for a name not a string).
    """
    if isinstance(name, Variant):
        return name
    if not isinstance(name, str):
        raise ParameterTypeError(f"variant {name!r} ({type(name).__name__}) is not a variant's name; allowed: "
                                 f"{', '.join(NAMES)}")
    key = ALIASES.get(name, name)
    if key in VARIANTS:
        return VARIANTS[key]
    raise ParameterError(f"variant {name!r} is unknown (a model in an engine, ENGINE-MODEL[-RULE]); allowed: "
                         f"{', '.join(NAMES)}")


def from_flags(engine: str = "analytic", geometry: str | None = None, rule: str | None = "kinematic",
               clutch: str | None = None, model: str = "slides") -> Variant:
    """The variant the command line's ``--engine``, ``--geometry``, ``--clutch``, ``--mujoco-clutch`` and
    ``--mujoco-model`` name (each refused in one line where it does not apply): the analytic geometry defaults
    to the paper's first order, MuJoCo's clutch to the lock for the paper's rule and to the ratchet for one-way
    clutches; ``rule`` None is the paper's rule, or one-way clutches on the wheeled model (its only ones)."""
    if model not in MUJOCO_MODELS:
        raise ParameterError(f"--mujoco-model {model!r} is unknown; allowed: {', '.join(MUJOCO_MODELS)}")
    if model != "slides":
        return _model_from_flags(engine, geometry, rule, clutch, model)
    rule = "kinematic" if rule is None else rule
    if engine not in ENGINES:
        raise ParameterError(f"--engine {engine!r} is unknown; allowed: {', '.join(ENGINES)}")
    if rule not in RULES:
        raise ParameterError(f"--clutch {rule!r} is unknown; allowed: {', '.join(RULES)}")
    if engine == "analytic":
        if clutch is not None:
            raise ParameterError(f"--mujoco-clutch {clutch} applies only to --engine mujoco")
        geometry = geometry or "approx"
        if geometry not in ("approx", "exact"):
            raise ParameterError(f"--geometry {geometry!r} is unknown; allowed: approx, exact")
        return _find(engine, rule, geometry, None)
    if geometry == "approx":
        raise ParameterError("--geometry approx with --engine mujoco: MuJoCo always models the real linkage; "
                             "allowed: --geometry exact (or leave it out)")
    clutch = clutch or ("lock" if rule == "kinematic" else "ratchet")
    if clutch == "ratchet" and rule == "kinematic":
        raise ParameterError("--clutch kinematic with the ratchet: a ratchet is a one-way clutch; use "
                             "--mujoco-clutch lock for the paper's rule, or --clutch unilateral")
    if clutch not in MUJOCO_CLUTCHES:
        raise ParameterError(f"--mujoco-clutch {clutch!r} is unknown; allowed: {', '.join(MUJOCO_CLUTCHES)}")
    return _find(engine, rule, "exact", clutch)


def _model_from_flags(engine: str, geometry: str | None, rule: str | None, clutch: str | None,
                      model: str) -> Variant:
    """The one variant of MuJoCo's model ``model`` (not the slides: ``mujoco-wheels`` for 'wheels'), after
    refusing the flags it does not take (one line each)."""
    v = next(v for v in VARIANTS.values() if v.model == model)
    if engine != "mujoco":
        raise ParameterError(f"--mujoco-model {model} applies only to --engine mujoco")
    if geometry == "approx":
        raise ParameterError("--geometry approx with --engine mujoco: MuJoCo always models the real linkage; "
                             "allowed: --geometry exact (or leave it out)")
    if rule not in (None, v.rule):
        raise ParameterError(f"--clutch {rule} with --mujoco-model {model}: its clutches are {v.clutches}; "
                             f"allowed: --clutch {v.rule} (or leave it out)")
    if clutch not in (None, v.clutch):
        raise ParameterError(f"--mujoco-clutch {clutch} with --mujoco-model {model}: its clutches are {v.clutches}; "
                             f"allowed: --mujoco-clutch {v.clutch} (or leave it out)")
    return v


def _find(engine: str, rule: str, geometry: str, clutch: str | None) -> Variant:
    return next(v for v in VARIANTS.values()
                if (v.engine, v.rule, v.geometry, v.clutch, v.model) == (engine, rule, geometry, clutch, "slides"))
