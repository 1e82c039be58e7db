"""Where the default ``cornering_coefficient`` comes from: Kalker's linear rolling-contact theory for the model's wheel.

Run on demand from the repository root (instant):

    python bench/cornering_coefficient.py [--set NAME=VALUE]... [--smoke]

A solid elastomer wheel rolling on a rigid wall at a small slip angle alpha carries a side force F = G c^2 C22
alpha (Kalker's linear theory of rolling contact: J. J. Kalker, "On the rolling contact of two elastic bodies in
the presence of dry friction", thesis, Delft 1967; K. L. Johnson, "Contact Mechanics", 1985, ch. 8): G the
elastomer's shear modulus, c the radius of the contact (Hertz), C22 Kalker's lateral creep coefficient, 3.98 for
a circular contact of an incompressible material (Poisson's ratio 0.5). Hertz: c^3 = 3 P R* / (4 E*), E* = E /
(1 - nu^2) against a rigid wall, R* = 1 / sqrt(k1 k2) the contact's equivalent radius, k1 = 1 / R along the
rolling direction (a crowned wheel, the model's sphere, on a straight wall) and k2 = 1 / R - 2 / D round the
pipe (the concave wall). So the cornering coefficient F / (P alpha) is

    C22 / 3 (9 / 16)^(2/3) (E R*^2 / P)^(1/3)      (nu = 0.5, G = E / 3)

The elastomer's Young's modulus from its Shore A hardness S by Gent's relation (A. N. Gent, Trans. Inst. Rubber
Ind. 34, 1958): E [MPa] = 0.0981 (56 + 7.66 S) / (0.137505 (254 - 2.54 S)). Prints the coefficient of the model's
wheel (``wheel_radius``, ``pipe_diameter``, the preload of the default F_n1) for Shore 60A (soft rubber) to 95A
(hard polyurethane). The default 8 /rad is a 90A polyurethane wheel's.
"""

from __future__ import annotations

import argparse
import math
import sys

from ipir_mujoco.core.params import RobotParams, parse_overrides

C22 = 3.98  # Kalker's lateral creep coefficient, circular contact, Poisson's ratio 0.5


def young_modulus(shore_a: float) -> float:
    """Young's modulus [Pa] of an elastomer of Shore A hardness ``shore_a`` (Gent's relation)."""
    return 1e6 * 0.0981 * (56 + 7.66 * shore_a) / (0.137505 * (254 - 2.54 * shore_a))


def coefficient(E: float, radius: float, diameter: float, preload: float) -> tuple[float, float]:
    """(the cornering coefficient [1/rad], the contact's radius [m]) of a wheel of Young's modulus ``E`` [Pa],
    radius ``radius`` [m] in a pipe of diameter ``diameter`` [m], pressed with ``preload`` [N] (module docstring)."""
    k1, k2 = 1.0 / radius, 1.0 / radius - 2.0 / diameter
    r_eq = 1.0 / math.sqrt(k1 * k2)
    contact = (3 * preload * r_eq / (4 * E / 0.75)) ** (1 / 3)
    return (E / 3) * contact ** 2 * C22 / preload, contact


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--smoke", action="store_true", help="the same (it runs nothing): the suite's flag")
    args = parser.parse_args(argv)
    p = RobotParams(**parse_overrides(args.set))
    P = p.F_n1 / (2 * p.wheel_legs)
    print(f"wheel radius {p.wheel_radius:g} m, pipe {p.pipe_diameter:g} m, preload {P:.3g} N")
    print("| Shore A | E [MPa] | contact radius [mm] | cornering coefficient [1/rad] |")
    print("|---|---|---|---|")
    for shore in (60, 70, 80, 85, 90, 95):
        E = young_modulus(shore)
        c, contact = coefficient(E, p.wheel_radius, p.pipe_diameter, P)
        print(f"| {shore} | {E / 1e6:.1f} | {contact * 1e3:.2f} | {c:.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
