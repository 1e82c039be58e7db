"""A ring of the round-pipe robot's wheels moving across the pipe on its legs' springs (:mod:`.wheel_checks`).

A ring's place is written as the load its springs carry there [N] (k_r d, k_r = n k / 2 its springs' stiffness
across the pipe, d its shift), so the loads on it and its place share one unit; each ring is half its module's
sprung mass on k_r: natural frequency omega = sqrt(n k / m). :func:`ring_response` moves one ring, undamped (its
wheels slide, or rigid wheels), in closed form; :func:`rings_motion` moves a module's two rings together where
its steer-compliant wheels roll (their cornering force a damper, and the module's heading steering both rings).
"""

from __future__ import annotations

import math

import numpy as np


def ring_response(spring: np.ndarray, grip: np.ndarray, step: float) -> np.ndarray:
    """Where a ring sits [N: the springs' load that holds it there] at each sample, shape (n, 2): a mass on its
    springs, undamped, pushed by ``spring`` (shape (n, 2)) held over each interval, ``step`` = omega dt its
    natural frequency times the interval; at rest, where it is, while its wheels hold (``grip``, shape (n,)).
    Exact for a load constant over each interval: with w = place + i velocity / omega, each interval turns
    w - load by -``step``: w' = a w + (1 - a) load, a = exp(-i step), summed in closed form over each stretch
    of samples where the wheels slide (from rest where they held)."""
    spring = np.asarray(spring, dtype=float).reshape(-1, 2)
    grip = np.asarray(grip, dtype=bool).reshape(-1)
    out = np.zeros_like(spring)
    free = np.flatnonzero(~grip)
    if not free.size:
        return out
    breaks = np.flatnonzero(np.diff(free) > 1)
    starts = np.concatenate([[free[0]], free[breaks + 1]])
    ends = np.concatenate([free[breaks] + 1, [free[-1] + 1]])
    a = complex(math.cos(step), -math.sin(step))
    place = np.zeros(2)
    last = 0
    for j0, j1 in zip(starts, ends):
        out[last:j0] = place  # held since the last stretch: where the ring stopped, at rest
        k = np.arange(j1 - j0 + 1)
        turn = np.exp(-1j * step * k)  # a^k
        back = np.exp(1j * step * (k[:-1] + 1))  # a^-(m + 1)
        for c in (0, 1):
            w = turn * (place[c] + (1 - a) * np.concatenate([[0.0], np.cumsum(back * spring[j0:j1, c])]))
            out[j0:j1, c] = w.real[:-1]  # the place at each sample's start; after the last, the place it stops at
            place[c] = w.real[-1]
        last = j1
    out[last:] = place
    return out


def rings_motion(springs, stills, dampings, omega: float, dt: float, steer: float,
                 walls: tuple | None = None, slips=None) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Where a module's aft and fore rings sit [N: the springs' load that holds each there] at each sample's start,
    shapes (n, 2), and whether each slides on its wheels over each sample, shapes (n,): each a mass on its springs
    (natural frequency ``omega`` [rad/s]) pushed by its ``springs`` load (shape (n, 2)) held over each interval
    ``dt`` [s], at rest where it is while ``stills`` (shape (n,)). Where its damping rate ``dampings`` [1/s] (per
    sample; c / m, inf: it does not move) is above 0 its wheels roll on their cornering compliance: their side force
    is C_r (psi - d' / v) per ring, the damping and the module's heading psi = (d_fore - d_aft) / s, which steers
    both rings the way the nose points with ``steer`` (X_fore - X_aft) (steer = C_r / (k_r s) = cornering_coefficient
    suspension_travel / ring_spacing), taken at each interval's start. That force ends at the wheels' friction:
    where it would pass it (``walls``: :func:`wheel_walls`, each wheel's friction mu_wall times its press at the
    ring's place; None: no end) they slide, their friction along the force over the interval, undamped. A ring with no damping slides.
    ``slips`` (per ring, shape (n, 2) [N], or None): the wheels' side force of a slip angle the pipe gives them (a
    bend's, :func:`ipir_mujoco.core.route_loads.route_loads`), added to the heading's.
    Exact for coefficients and loads constant over an interval (the interval's matrix exponential), the heading
    held at its start (:func:`ring_response` sums one undamped ring in closed form)."""
    count = np.asarray(springs[0]).reshape(-1, 2).shape[0]
    rate_list, coefficients = [], []
    for damping in dampings:
        half = 0.5 * np.broadcast_to(np.asarray(damping, dtype=float), (count,))
        stiff = ~np.isfinite(half)  # a damper without end: the ring stays where it is, as a still one
        half = np.where(stiff, 0.0, half)
        root = np.sqrt(half * half - omega * omega + 0j)
        # the two modes' decays over the interval, e^((-h +- root) dt), the slow one as -omega^2 / (h + root) (the
        # same number, without the cancellation of a heavy damping's h - root)
        slow = np.exp(-omega * omega / (half + root) * dt)
        fast = np.exp(-(half + root) * dt)
        mean = 0.5 * (slow + fast)  # e^(-h dt) cosh(root dt)
        small = np.abs(root) * dt < 1e-7
        sinc = np.where(small, dt * np.exp(-half * dt), (slow - fast) / (2 * np.where(small, 1.0, root)))
        coefficients.append(((mean + sinc * half).real.tolist(), sinc.real.tolist(),
                             (-omega * omega * sinc).real.tolist(), (mean - sinc * half).real.tolist()))
        rate_list.append(np.where(stiff, math.inf, 2.0 * half / (omega * omega)).tolist())  # force per place rate
    c0, s0 = math.cos(omega * dt), math.sin(omega * dt)  # undamped, sliding
    if walls is not None:
        legs = [(float(a), float(b), float(c), float(d)) for (a, b), (c, d) in zip(walls[0], walls[1])]
        preload, mu, share = walls[2], walls[4], 2.0 / len(legs)
        weights = np.broadcast_to(np.asarray(walls[3], dtype=float).reshape(-1, 2), (count, 2)).tolist()
    loads = [np.asarray(sp, dtype=float).reshape(-1, 2).tolist() for sp in springs]
    rests = [np.asarray(st, dtype=bool).reshape(-1).tolist() for st in stills]
    bends = [None if slips is None or slip is None else np.asarray(slip, dtype=float).reshape(-1, 2).tolist()
             for slip in (slips or (None, None))]
    places = [np.empty((count, 2)), np.empty((count, 2))]
    slid = [np.zeros(count, dtype=bool), np.zeros(count, dtype=bool)]
    x, v = [[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]]
    for j in range(count):
        places[0][j], places[1][j] = x[0], x[1]
        turned = (steer * (x[1][0] - x[0][0]), steer * (x[1][1] - x[0][1]))
        for r in (0, 1):
            heading = turned if bends[r] is None else (turned[0] + bends[r][j][0], turned[1] + bends[r][j][1])
            rate = rate_list[r][j]
            if rests[r][j] or rate == math.inf:
                v[r] = [0.0, 0.0]
                continue
            xr, vr, load = x[r], v[r], loads[r][j]
            sliding = rate == 0.0
            if not sliding:
                push = (heading[0] - rate * vr[0], heading[1] - rate * vr[1])
                w0, w1 = weights[j] if walls is not None else (0.0, 0.0)
                size = math.hypot(*push)
                friction = 0.0 if walls is None or size == 0.0 else mu * sum(
                    max(preload + share * ((xr[0] + w0) * u0 + (xr[1] + w1) * u1), 0.0)
                    * abs(e0 * push[0] + e1 * push[1]) for u0, u1, e0, e1 in legs) / size
                if walls is not None and size > friction:  # the wheels slide: their friction along their force
                    load = [load[0] + friction * push[0] / size, load[1] + friction * push[1] / size]
                    sliding = True
                else:
                    load = [load[0] + heading[0], load[1] + heading[1]]
            if sliding:
                slid[r][j] = True
                for a in (0, 1):
                    d = xr[a] - load[a]
                    xr[a], vr[a] = load[a] + c0 * d + s0 / omega * vr[a], -omega * s0 * d + c0 * vr[a]
                continue
            p11, p12, p21, p22 = (c[j] for c in coefficients[r])
            for a in (0, 1):
                d = xr[a] - load[a]
                xr[a], vr[a] = load[a] + p11 * d + p12 * vr[a], p21 * d + p22 * vr[a]
    return places, slid
