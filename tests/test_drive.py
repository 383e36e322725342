"""Drive dynamics: the classic torque-arm formula, the energy balance, an independent integration of
trajectory.csv, the motor's limits in the plan and the bound, and the drive's input checks."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from planning.cli import main
from planning.model.case_file import case_from_data, load_yaml, read_case
from planning.model.drive import drive_figures
from planning.solver.bound import time_optimal_bound
from planning.solver.optimize import solve
from press.crank_slider import CrankSlider
from press.dynamics import DriveModel, crank_torque, motor_torque

from .conftest import PUBLISHED_CASE, ROOT
from .conftest import solved as solved_case

DRIVE_CASES = [ROOT / "cases" / "wang2023-side-panel-drive.yaml", ROOT / "cases" / "cup-2000kN-drive.yaml"]
# every mechanism's: the linkages' links carry their own masses (Lagrange's equation, ``press.dynamics``)
EVERY_MECHANISM = [
    *DRIVE_CASES,
    ROOT / "cases" / "link-drive-side-panel.yaml",
    ROOT / "cases" / "knuckle-joint-coining.yaml",
]
INTEGRATION_TOL = 1e-3  # relative: the trapezoidal rule on the 1 ms trajectory against the solver's quadrature


def data_of(path: Path) -> dict:
    return load_yaml(path.read_text())


@pytest.fixture(scope="module", params=EVERY_MECHANISM, ids=lambda p: p.stem)
def solved(request, tmp_path_factory):
    out = tmp_path_factory.mktemp("drive") / "out"
    assert main(["solve", str(request.param), "--out", str(out), "--no-plots"]) == 0
    return request.param, out


@pytest.mark.parametrize("R, L", [(450.0, 1200.0), (125.0, 600.0), (50.0, 250.0)])
def test_quasi_static_torque_is_the_torque_arm_formula(R, L):
    """Masses and inertias zero, eta = 1, i = 1: T = F R (sin a + cos a tan b), a = 180 deg - theta the
    crank angle before BDC, b the rod angle (the press-rating formula)."""
    F = 2.5e6  # [N] upward on the descending slide
    still = DriveModel(
        M=0.0, J0=0.0, F_cb=0.0, i=1.0, eta=1.0, J_m=0.0, force_heights=(), force_values=(), draw_start=0.0, bdc=math.pi
    )
    theta = np.linspace(0.05, math.pi - 0.05, 200)
    d1, d2, _ = CrankSlider(R, L).derivatives(theta)
    torque = motor_torque(crank_torque(3.0, 0.0, d1, d2, F, still), 0.0, still)
    a = math.pi - theta
    b = np.arcsin(R * np.sin(a) / L)
    classic = F * (R * 1e-3) * (np.sin(a) + np.cos(a) * np.tan(b))
    np.testing.assert_allclose(torque, classic, rtol=1e-9, atol=0)


def test_power_flow_signs():
    """Losses always cost the supply: driving needs more motor torque than T_c / i, braking returns less."""
    drive = DriveModel(
        M=0.0,
        J0=0.0,
        F_cb=0.0,
        i=10.0,
        eta=0.9,
        J_m=0.0,
        force_heights=(),
        force_values=(),
        draw_start=0.0,
        bdc=math.pi,
    )
    assert motor_torque(np.array(100.0), 0.0, drive) == pytest.approx(100.0 / (10 * 0.9))
    assert motor_torque(np.array(-100.0), 0.0, drive) == pytest.approx(-100.0 * 0.9 / 10)


@pytest.mark.parametrize("path", EVERY_MECHANISM, ids=lambda p: p.stem)
def test_energy_balance_over_a_cycle(path):
    """Kinetic energy is periodic, gravity and the counterbalance conservative: the crank's work per
    stroke is the forming work of the table, integrated independently (exactly, over the height); a
    linkage's links and their weight included."""
    case = read_case(path)
    sol = solved_case(path)
    fig = drive_figures(sol.plan.profile, case)
    assert fig.forming_work_kJ > 0
    assert fig.crank_work_kJ == pytest.approx(fig.forming_work_kJ, rel=1e-9)
    assert fig.energy_net_kJ > fig.forming_work_kJ  # the gear's losses come on top
    check = next(c for c in sol.verification.checks if c.name.startswith("energy balance"))
    assert check.passed


def test_without_forming_the_crank_does_no_net_work():
    data = data_of(DRIVE_CASES[0])
    del data["process"]["forming_force_kN"]
    case = case_from_data(data)
    fig = drive_figures(solve(case).plan.profile, case)
    assert abs(fig.crank_work_kJ) <= 1e-8 * fig.crank_work_abs_kJ


def test_trajectory_integrated_independently_gives_the_drive_figures(solved):
    """Peak and RMS motor torque and the energies from trajectory.csv (trapezoids on the 1 ms grid)."""
    _, out = solved
    drive = json.loads((out / "result.json").read_text())["drive"]
    rows = np.genfromtxt(out / "trajectory.csv", delimiter=",", names=True)
    t, tm, p = rows["time_s"], rows["motor_torque_Nm"], rows["motor_power_kW"] * 1e3
    period = t[-1] - t[0]

    def integral(y):
        return float(np.sum(np.diff(t) * (y[1:] + y[:-1]) / 2))

    assert float(np.max(np.abs(tm))) == pytest.approx(drive["peak_motor_torque_Nm"], rel=INTEGRATION_TOL)
    assert math.sqrt(integral(tm**2) / period) == pytest.approx(drive["rms_motor_torque_Nm"], rel=INTEGRATION_TOL)
    assert integral(np.maximum(p, 0)) / 1e3 == pytest.approx(drive["energy_drawn_kJ"], rel=INTEGRATION_TOL)
    assert integral(np.minimum(p, 0)) / 1e3 == pytest.approx(drive["energy_returned_kJ"], rel=INTEGRATION_TOL)
    assert float(np.max(rows["motor_speed_rpm"])) <= drive["motor"]["max_speed_rpm"] * (1 + 1e-6)


def test_plan_respects_the_envelope_and_the_rms_limit_on_the_sample_times(solved):
    path, out = solved
    result = json.loads((out / "result.json").read_text())
    checks = {c["name"]: c for c in result["verification"]["checks"]}
    for name in ("motor peak torque", "motor speed", "motor RMS torque", "energy balance: crank work = forming work"):
        assert checks[name]["passed"], name
    motor = result["drive"]["motor"]
    rows = np.genfromtxt(out / "trajectory.csv", delimiter=",", names=True)
    n = rows["motor_speed_rpm"]
    envelope = motor["peak_torque_Nm"] * np.minimum(1.0, motor["base_speed_rpm"] / n)
    assert np.all(np.abs(rows["motor_torque_Nm"]) <= envelope * (1 + 1e-6))


def test_the_rms_limit_binds_and_a_tenfold_motor_gives_back_the_kinematic_optimum():
    data = data_of(DRIVE_CASES[0])
    limited = solve(case_from_data(data))
    assert "motor_rms_torque" in [c.id for c in limited.verification.binding()]  # at its limit within 1e-4
    kinematic = solved_case(PUBLISHED_CASE)
    assert limited.plan.spm < kinematic.plan.spm * 0.95
    for key in ("peak_torque_Nm", "rated_torque_Nm", "max_speed_rpm"):
        data["drive"]["motor"][key] *= 10
    strong = solve(case_from_data(data))
    assert strong.plan.spm == pytest.approx(kinematic.plan.spm, rel=1e-3)


def test_motor_speed_caps_the_crank():
    data = data_of(DRIVE_CASES[0])
    data["drive"]["motor"]["rated_torque_Nm"] = 60000.0
    data["drive"]["motor"]["peak_torque_Nm"] = 90000.0
    data["drive"]["motor"]["max_speed_rpm"] = 600.0  # 20 rpm at the crank
    case = case_from_data(data)
    sol = solve(case)
    assert drive_figures(sol.plan.profile, case).peak_motor_speed_rpm <= 600.0 * (1 + 1e-6)
    assert time_optimal_bound(case).spm >= sol.plan.spm


@pytest.mark.parametrize("path", EVERY_MECHANISM, ids=lambda p: p.stem)
def test_bound_stays_above_the_drive_plan(path):
    case = read_case(path)
    assert time_optimal_bound(case, 720).spm >= solved_case(path).plan.spm


def test_a_motor_too_weak_for_the_draw_is_exit_3_naming_it(tmp_path, capsys):
    text = DRIVE_CASES[0].read_text().replace("peak_torque_Nm: 72000", "peak_torque_Nm: 50000")
    path = tmp_path / "weak.yaml"
    path.write_text(text)
    assert main(["solve", str(path), "--out", str(tmp_path / "o")]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "infeasible" in err[0] and "drive.motor.peak_torque_Nm" in err[0] and "deg" in err[0]


@pytest.mark.parametrize(
    "old, new, field",
    [
        ("rated_torque_Nm: 20000", "rated_torque_Nm: 80000", "drive.motor.rated_torque_Nm"),
        ("gear_efficiency: 0.93", "gear_efficiency: 1.5", "drive.gear_efficiency"),
        ("base_speed_rpm: 500", "base_speed_rpm: 5000", "drive.motor.base_speed_rpm"),
        ("rod_cg_from_crank_pin_mm: 480", "rod_cg_from_crank_pin_mm: 4800", "drive.rod_cg_from_crank_pin_mm"),
        ("slide_mass_kg: 65000", "slide_mass_kg: -1", "drive.slide_mass_kg"),
        ("[200, 0], [180, 4500]", "[200, 0], [1800, 4500]", "process.forming_force_kN.1"),
        ("gear_ratio: 30", "gear_ratio: thirty", "drive.gear_ratio"),
    ],
)
def test_bad_drive_field_is_exit_2_naming_it(old, new, field, tmp_path, capsys):
    text = DRIVE_CASES[0].read_text()
    assert old in text
    path = tmp_path / "bad.yaml"
    path.write_text(text.replace(old, new))
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0]


def test_a_motor_too_small_for_the_draws_heat_is_exit_3_naming_it(tmp_path, capsys):
    """The draw alone over the longest cycle the minimum crank speed allows already overheats a motor
    rated 4 kN m (at least 6.56 kN m RMS): proven before any solve, so `infeasible`."""
    text = DRIVE_CASES[0].read_text().replace("rated_torque_Nm: 20000", "rated_torque_Nm: 4000")
    path = tmp_path / "hot.yaml"
    path.write_text(text)
    assert main(["solve", str(path), "--out", str(tmp_path / "o")]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "infeasible: drive.motor.rated_torque_Nm = 4000" in err[0]
    assert "limits.min_crank_speed_rpm" in err[0]


def test_the_drive_nlps_draw_rows_depend_on_the_draw_speed_alone():
    """The drive NLP samples the draw at its fixed angles and constant speed (``planning.solver.halves_nlp``):
    each of its motor-torque rows there has one nonzero in the constraint Jacobian, the draw speed's. The
    slider acceleration has no rows in the draw: at constant speed the draw speed's bound holds it exactly
    (``planning.model.limits.slider_accel``)."""
    from planning.solver.halves_nlp import VARIABLE_INDEX, halves_nlp_for
    from planning.solver.parameters import FORMING_SAMPLES

    nlp = halves_nlp_for(read_case(DRIVE_CASES[0]), drive=True)
    pattern = nlp.program._cold.get_function("nlp_jac_g").sparsity_out(1)
    rows, cols = (np.array(a) for a in pattern.get_triplet())
    torque = nlp.block_of("motor_peak_torque")
    draw = (rows >= torque.stop - FORMING_SAMPLES) & (rows < torque.stop)
    assert set(cols[draw].tolist()) == {VARIABLE_INDEX["draw_speed"]}
    assert len(set(rows[draw].tolist())) == FORMING_SAMPLES
    outside = (rows >= torque.start) & (rows < torque.stop - FORMING_SAMPLES)
    assert len(set(cols[outside].tolist())) > 5  # the other samples follow the cycle's closed form
    accel = nlp.block_of("slider_accel")
    assert accel.stop - accel.start == torque.stop - torque.start - FORMING_SAMPLES


def test_a_binding_rms_limit_is_used_to_the_rating():
    """The NLP's RMS row is a trapezoid over its samples; on the cup press with a smaller motor (rated 2160 N m)
    it overestimates the heat by about 4e-4, and the plan kept that much of the rating unused (RMS 2159.2 N m,
    not listed as binding). The solve raises the row's limit by the measured gap: the plan uses the rating to
    within the binding share and the binding list names the RMS limit."""
    data = data_of(DRIVE_CASES[1])
    data["drive"]["motor"]["rated_torque_Nm"] = 2160.0
    sol = solve(case_from_data(data))
    rms = sol.verification.check("motor_rms_torque")
    assert rms.passed and rms.margin <= 1e-4 * rms.limit
    assert "motor_rms_torque" in [c.id for c in sol.verification.binding()]
