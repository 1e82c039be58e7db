"""Slider-crank kinematics: first-order (the paper's, L >> r) and exact.

Frame: x along the pipe (forward), y across it in the plane of the crank; the
origin is the crank axis A. The crank angle ``phi`` is measured from +x, so
phi = 0 is full extension. C (the rod's pin on module 2) stays on the x axis.

Every function takes ``phi`` as a float or an ndarray of any shape [rad] and
returns values of the same shape; lengths are in metres.
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from enum import Enum
from typing import NamedTuple

import numpy as np


class Geometry(str, Enum):
    """Which kinematics relate the crank angle to the module gap."""

    APPROX = "approx"  # the paper's first order: S = L + r cos(phi)
    EXACT = "exact"  # in-line slider-crank: S = r cos(phi) + sqrt(L^2 - r^2 sin^2(phi))


class Transfer(NamedTuple):
    """Gap and its derivatives with respect to the crank angle."""

    S: np.ndarray  # gap x2 - x1 [m]
    K: np.ndarray  # dS/dphi [m/rad]
    dK: np.ndarray  # d2S/dphi2 [m/rad^2]


class RodMotion(NamedTuple):
    """Rod centre-of-mass and angle velocities per unit crank speed, relative to A.

    With x1 fixed: G_x_dot = a * phi_dot, G_y_dot = b * phi_dot,
    beta_dot = g * phi_dot (beta = rod angle from +x). ``da``, ``db``, ``dg``
    are their derivatives with respect to phi. Only the exact geometry has a
    rod of fixed length, so only it defines these.
    """

    a: np.ndarray
    b: np.ndarray
    g: np.ndarray
    da: np.ndarray
    db: np.ndarray
    dg: np.ndarray


def _functions(phi):
    """(sin, cos, sqrt) for ``phi``: math's for one float (the event loop's single states: no numpy
    call per evaluation), numpy's for arrays."""
    return (math.sin, math.cos, math.sqrt) if isinstance(phi, float) else (np.sin, np.cos, np.sqrt)


class Linkage:
    """The crank AB (length r) and rod BC (length L) in one geometry."""

    def __init__(self, r: float, L: float, geometry: Geometry | str):
        self.r = float(r)
        self.L = float(L)
        self.geometry = Geometry(geometry)
        if self.geometry is Geometry.EXACT and not self.L > self.r:
            raise ValueError(f"exact slider-crank needs L > r, got L={L} m, r={r} m")
        self._last = (math.nan, None)  # (phi, transfer) of the last single angle: a mode switch asks for it 3 times
        self._memo: dict | None = None  # see reusing

    @contextmanager
    def reusing(self):
        """Within this context, :meth:`transfer`, :meth:`rod_motion` and the rod's projection of one and the
        same array object are computed once (that array must not change meanwhile): a run's post-processing
        asks for them of the same samples a dozen times."""
        self._memo = {}
        try:
            yield self
        finally:
            self._memo = None

    def _remembered(self, name: str, compute, phi):
        """compute(phi), or its value from :meth:`reusing`'s memo for this very array."""
        memo = self._memo
        if memo is None or not isinstance(phi, np.ndarray):
            return compute(phi)
        seen = memo.get((name, id(phi)))
        if seen is None or seen[0] is not phi:
            value = compute(phi)
            for array in (value if isinstance(value, tuple) else (value,)):
                if isinstance(array, np.ndarray):
                    array.flags.writeable = False  # shared by every later caller: none may change it
            seen = memo[(name, id(phi))] = (phi, value)  # phi kept alive: its id stays its own
        return seen[1]

    def _root(self, phi):
        """sqrt(L^2 - r^2 sin^2 phi): the rod's projection on x [m] (exact geometry)."""
        return self._remembered("root", self._compute_root, phi)

    def _compute_root(self, phi):
        sin, _, sqrt = _functions(phi)
        return sqrt(self.L**2 - (self.r * sin(phi)) ** 2)

    def transfer(self, phi) -> Transfer:
        """S(phi), K = dS/dphi and dK/dphi."""
        if isinstance(phi, float):
            last, found = self._last
            # -0.0 == 0.0, but their K differ in sign (transfer(0.0).K is -0.0, transfer(-0.0).K is +0.0)
            if phi == last and math.copysign(1.0, phi) == math.copysign(1.0, last):
                return found
            found = self._transfer(phi)
            self._last = (phi, found)
            return found
        return self._remembered("transfer", self._transfer, phi)

    def _transfer(self, phi) -> Transfer:
        sin, cos, _ = _functions(phi)
        r, s, c = self.r, sin(phi), cos(phi)
        if self.geometry is Geometry.APPROX:
            return Transfer(self.L + r * c, -r * s, -r * c)
        D = self._root(phi)
        S = r * c + D
        K = -r * s - r**2 * s * c / D
        dK = -r * c - r**2 * (c**2 - s**2) / D - r**4 * s**2 * c**2 / D**3
        return Transfer(S, K, dK)

    def gap(self, phi):
        """Module gap S = x2 - x1 [m]."""
        return self.transfer(phi).S

    def crank_pin(self, phi) -> tuple[np.ndarray, np.ndarray]:
        """Position of B relative to A, (x, y) [m]."""
        return self.r * np.cos(phi), self.r * np.sin(phi)

    def rod_com(self, phi) -> tuple[np.ndarray, np.ndarray]:
        """Position of the rod's centre of mass (mid-point of BC) relative to A, (x, y) [m]."""
        bx, by = self.crank_pin(phi)
        return 0.5 * (bx + self.gap(phi)), 0.5 * by

    def rod_motion(self, phi) -> RodMotion:
        """Velocity coefficients of the rod (exact geometry only; see :class:`RodMotion`)."""
        if self.geometry is not Geometry.EXACT:
            raise ValueError("the first-order geometry has no rigid rod; rod motion needs geometry 'exact'")
        return self._remembered("rod", self._rod_motion, phi)

    def _rod_motion(self, phi) -> RodMotion:
        sin, cos, _ = _functions(phi)
        r, s, c = self.r, sin(phi), cos(phi)
        D = self._root(phi)
        _, K, dK = self.transfer(phi)
        # G = (B + C)/2 with B = (r c, r s), C = (S, 0).
        a = 0.5 * (-r * s + K)
        b = 0.5 * r * c
        da = 0.5 * (-r * c + dK)
        db = -0.5 * r * s
        # sin(beta) = -r s / L and L cos(beta) = D, so beta_dot = -r c / D * phi_dot.
        g = -r * c / D
        dg = r * s / D - r**3 * s * c**2 / D**3
        return RodMotion(a, b, g, da, db, dg)
