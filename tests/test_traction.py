"""Traction limits (studies/climb/traction.py), their place in ``climb``, and the validation report's Finite grip
section.

Hand checks (docs/model.md, "Finite grip"; docs/cli.md, the climb worked example). A standing robot's
holds are statics: with the drive off each module holds its own weight share, module 2 with the rod's
share m_rod (1 + D/S) / 2, largest at phi = pi (D/S = L/(L - r)), module 1 the rest, largest at phi = 0
(share m_rod (1 + L/(L + r)) / 2 on module 2). With the drive's torque at rest, where it moves the other
module (ground force -F_rj), the held one holds the whole weight and that resistance, m g s + F_rj.
The limits are extremes over phi found by a scan and a bounded refinement to 1e-12 rad of a smooth
extremum, so they match the closed forms to roundoff: REL = 1e-9 relative.
"""

from __future__ import annotations

import math

import pytest

from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.studies import climbing, traction

REL = 1e-9  # relative: a refined extremum of a smooth function, against a closed form (module docstring)


def _shares(p: RobotParams) -> tuple[float, float]:
    """[kg]: the largest weight share each module holds at rest with the drive off (module docstring)."""
    m2 = p.m2 + p.rod_mass * 0.5 * (1.0 + p.L / (p.L - p.r))
    m1 = p.m1 + p.rod_mass - p.rod_mass * 0.5 * (1.0 + p.L / (p.L + p.r))
    return m1, m2


@pytest.mark.parametrize("m1", [1.0, 1.5])  # module 2 binds (the rod's share) / module 1 binds (heavier)
def test_rest_limit_drive_off_is_each_module_holding_its_weight(m1):
    p = RobotParams(m1=m1, mu_wall=0.5, F_n1=10.0, F_n2=10.0)  # G = 5 N, below either weight
    shares = _shares(p)
    hand = min(G / (m * p.g) for G, m in zip(p.grip, shares))
    rest = traction.rest_limit(p)
    assert rest["drive_off"]["sin"] == pytest.approx(hand, rel=REL)
    assert rest["drive_off"]["module"] == (1 if m1 == 1.5 else 2)
    assert rest["drive_off"]["incline_deg"] == pytest.approx(math.degrees(math.asin(hand)), rel=REL)
    # the drive at rest moves one module and the other holds the whole weight and its resistance
    moving = (m1 + p.m2 + p.rod_mass) * p.g
    assert rest["drive_at_rest"]["sin"] == pytest.approx((5.0 - 1.0) / moving, rel=REL)
    assert rest["binds"] == "drive_at_rest"


def test_rest_limit_any_incline_with_ample_grip():
    p = RobotParams(mu_wall=1.0, F_n1=100.0, F_n2=100.0)  # G = 100 N, five times the 20.7 N a module can need
    rest = traction.rest_limit(p)
    assert rest["drive_off"]["any_incline"] and rest["drive_at_rest"]["any_incline"]
    assert rest["drive_at_rest"]["incline_deg"] == 90.0


def test_riser_press_is_the_hand_check():
    p = RobotParams(mu_wall=0.5, F_n1=20.0, F_n2=20.0)
    riser = traction.riser_press(p)
    shares = _shares(p)
    for i in (0, 1):
        assert riser["press_n"]["drive_off"][i] == pytest.approx(shares[i] * p.g / 0.5, rel=REL)
        other = (p.F_r2, p.F_r1)[i]
        hand = ((p.m1 + p.m2 + p.rod_mass) * p.g + other) / 0.5  # (2.01 x 9.81 + 1) / 0.5 = 41.436 N
        assert riser["press_n"]["drive_at_rest"][i] == pytest.approx(hand, rel=REL)
        assert riser["needed_n"][i] == pytest.approx(hand, rel=REL)
    assert riser["binds"] == "drive_at_rest"
    # the press does not depend on the press given, only on mu_wall
    assert traction.riser_press(p.replace(F_n1=5.0, F_n2=5.0))["needed_n"] == riser["needed_n"]


@pytest.mark.slow
def test_unlimited_grip_changes_nothing_in_climb(tmp_path):
    from ipir_mujoco.cli import climb

    p = RobotParams(drive="torque")
    study = climbing.climb_study(p, [0.0], ("analytic-unilateral",), t_end=0.2)
    assert study["traction"] == {"grip": None, "note": traction.UNLIMITED}
    assert not {"slip_m", "peak_grip_use"} & set(study["rows"][0]["engines"]["analytic-unilateral"])
    text = climb.format_study(study, p)
    without = climb.format_study({k: v for k, v in study.items() if k != "traction"}, p)
    assert text.replace(f"  traction: {traction.UNLIMITED}\n", "") == without
    climb.write_csv(tmp_path / "climb.csv", study)
    header = (tmp_path / "climb.csv").read_text().splitlines()[0].split(",")
    assert header == ["incline_deg", "torque_needed_n_m"] + [f"analytic-unilateral:{k}" for k in climb.KEYS] + ["error"]


def test_finite_grip_climb_adds_its_figures(tmp_path):
    from ipir_mujoco.cli import climb

    p = RobotParams(drive="torque", mu_wall=0.5, F_n1=20.0, F_n2=20.0)
    study = climbing.climb_study(p, [0.0], ("analytic-unilateral", "mujoco-ratchet"), t_end=0.2)
    assert study["traction"]["grip"] == [10.0, 10.0] and study["traction"]["steady"] == {}  # no motor: no runs
    text = climb.format_study(study, p)
    assert "27.16 deg" in text  # asin(9 / (2.01 x 9.81)) = 27.157 deg
    assert "41.44 / 41.44 N" in text
    row = study["rows"][0]["engines"]
    assert "slip_m" in row["analytic-unilateral"]
    mujoco = row["mujoco-ratchet"]
    assert "error" in mujoco or "slip_m" in mujoco  # refused today; once MuJoCo models grip, measured


def test_steady_limit_skids_on_the_level_below_the_cruise_demand():
    # the motor's cruise demands 12.1 N (docs/model.md); G = 10 N skids in the steady window even on the level,
    # only at the peak of each stroke: tens of micrometres per window, a thousand times SLIP_TOL and more
    motor = RobotParams(drive="motor", mu_wall=0.5, F_n1=20.0, F_n2=20.0)
    limit = traction.steady_limit(motor, "analytic-unilateral", high=90.0)
    assert limit["incline_deg"] is None and limit["runs"][0]["steady_slip_m"] > 1e3 * traction.SLIP_TOL


@pytest.mark.slow
def test_grip_section_renders_quick_and_names_the_refusal(tmp_path):
    from ipir_mujoco.report import grip_section
    from ipir_mujoco.report.document import Image, Paragraph, Table

    metrics = grip_section.compute(RobotParams(), True, lambda _m: None)
    blocks = grip_section.render(metrics, tmp_path)
    assert (tmp_path / "finite_grip.png").is_file() and any(isinstance(b, Image) for b in blocks)
    startup, cruise = metrics["cases"]["startup"], metrics["cases"]["cruise"]
    # docs/model.md states the one-way model's demands as 67 N and 12.1 N: within half their last digit
    assert startup["unlimited"]["analytic-unilateral"]["peak_clutch_force_n"] == pytest.approx(67.0, abs=0.5)
    assert cruise["unlimited"]["analytic-unilateral"]["peak_clutch_force_n"] == pytest.approx(12.1, abs=0.05)
    # and the cruise on G = 5 N skids 1.9 + 2.6 cm: within the two half-digits, 0.1 cm
    five = next(r for r in cruise["rows"] if r["grip_n"] == 5.0)
    assert five["analytic-unilateral"]["slip_m"] == pytest.approx(0.045, abs=0.001)
    text = " ".join(b.text for b in blocks if isinstance(b, Paragraph))
    mujoco = five["mujoco-ratchet"]
    if "error" in mujoco:  # today: MuJoCo refuses a finite grip, and the section says which engine did
        assert "mujoco-ratchet" in text and "refused" in text and mujoco["error"] in text
    else:  # once it models grip, its figures are in the table
        table = next(b for b in blocks if isinstance(b, Table) and "MuJoCo (travel, speed)" in b.header)
        assert "refused" not in [row[-1] for row in table.rows]
    assert "41.44 / 41.44 N" in text  # the riser press at mu 0.5, as test_riser_press_is_the_hand_check
    assert grip_section.verdict(metrics)["answer"].startswith("The one-way model:")
