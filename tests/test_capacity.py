"""The press's own capacity (``press.capacity``): the tonnage curve against the crank-slider's closed form, a
forming force table above it refused in one line, the crank torque capacity binding on the shipped knuckle
joint and checked by the verification, the bound above the plan."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from planning.cli import main
from planning.model.case_file import read_case
from planning.solver.bound import time_optimal_bound
from planning.solver.verify import verify
from press.capacity import rated_torque_kNm, tonnage_curve
from press.crank_slider import CrankSlider

from .conftest import ROOT, solved

CUP = ROOT / "cases" / "cup-2000kN-drive.yaml"
KNUCKLE = ROOT / "cases" / "knuckle-joint-coining.yaml"


def _lever_m(R: float, L: float, phi: np.ndarray) -> np.ndarray:
    """|dh/dtheta| of an in-line crank press [m/rad], written out: the slide hangs on the rod below the crank pin
    ``(R sin phi, R cos phi)``, so it is at ``R cos phi - sqrt(L^2 - R^2 sin^2 phi)`` and ``h = that + L + R``
    above BDC (phi from TDC); ``dh/dphi = -R sin phi (1 - R cos phi / sqrt(L^2 - R^2 sin^2 phi))``."""
    return R * np.sin(phi) * (1 - R * np.cos(phi) / np.sqrt(L**2 - R**2 * np.sin(phi) ** 2)) * 1e-3


def test_the_tonnage_curve_is_the_rated_torque_over_the_crank_lever():
    """(2) of ``press.capacity`` against the closed form: above the rated distance the allowed force is the
    rated force times the lever at the rated distance over the lever there; below it the rated force."""
    R, L, force, distance = 125.0, 600.0, 2000.0, 8.0
    machine = CrankSlider(R, L)
    heights, allowed = tonnage_curve(machine, force, distance)
    phi = np.radians(np.linspace(20.0, 170.0, 31))
    h = R * np.cos(phi) - np.sqrt(L**2 - R**2 * np.sin(phi) ** 2) + L + R
    lo, hi = 0.0, math.pi  # the rated distance's angle on the down stroke, by bisection
    for _ in range(200):
        phi_r = 0.5 * (lo + hi)
        h_r = R * math.cos(phi_r) - math.sqrt(L**2 - R**2 * math.sin(phi_r) ** 2) + L + R
        lo, hi = (phi_r, hi) if h_r > distance else (lo, phi_r)
    torque = force * _lever_m(R, L, np.array([phi_r]))[0]
    assert rated_torque_kNm(machine, force, distance) == pytest.approx(torque, rel=1e-9)
    expected = np.minimum(force, torque / _lever_m(R, L, phi))
    assert np.allclose(np.interp(h, heights, allowed), expected, rtol=2e-4)  # the curve's own samples: 4001


def test_a_forming_force_above_the_tonnage_curve_is_refused_in_one_line(tmp_path, capsys):
    """The cup's forming force (773 kN at 60 mm) on a press rated at 6.5 mm: refused when the case is read,
    by ``check`` and ``solve``, one line naming the field, exit 2, nothing written."""
    for command in (["check"], ["solve", "--out", str(tmp_path / "o")]):
        code = main([*command[:1], str(CUP), *command[1:], "--set", "press.capacity.rated_distance_mm=6.5"])
        err = capsys.readouterr().err.strip()
        assert code == 2 and len(err.splitlines()) == 1, err
        assert "process.forming_force_kN" in err and "tonnage curve" in err and "767 kN" in err
    assert not (tmp_path / "o").exists()


def test_a_tonnage_table_is_read_and_a_forming_force_above_it_refused(tmp_path, capsys):
    """The builder's curve as a table (``press.capacity.force_table_kN``) instead of the rating: the cup's forming
    force (773 kN at 60 mm) under a table that allows 700 kN there is refused in one line naming the field (an
    outside trial found a traceback: the table made the press unhashable); under one that allows 2000 kN
    everywhere the case is checked and solves, verified."""
    data = yaml.safe_load(CUP.read_text(encoding="utf-8"))
    low = [[0, 2000], [50, 2000], [60, 700], [500, 700]]
    for table, expected in ((low, 2), ([[0, 2000], [500, 2000]], 0)):
        data["press"]["capacity"] = {"force_table_kN": table}
        path = tmp_path / "table.yaml"
        path.write_text(yaml.safe_dump(data), encoding="utf-8")
        assert main(["check", str(path)]) == expected
        err = capsys.readouterr().err.strip()
        if expected:
            assert len(err.splitlines()) == 1 and "process.forming_force_kN" in err and "(700 kN;" in err, err
    assert main(["solve", str(path), "--out", str(tmp_path / "o"), "--no-plots"]) == 0
    assert "verified" in capsys.readouterr().out


def test_the_crank_torque_capacity_binds_on_the_knuckle_joint_and_the_verification_sees_it():
    """The knuckle joint rated 6300 kN at 1.5 mm (57.7 kN m): the crank torque binds in the feed and the
    strokes fall against the same press without the rating; the plan without it breaks the capacity (the
    verification fails it), the time-optimal bound stays above the plan."""
    limited = solved(KNUCKLE)
    case = read_case(KNUCKLE)
    assert "crank_torque" in [c.id for c in limited.verification.binding()]
    free = solved(KNUCKLE, press__capacity__rated_distance_mm=50.0)  # a rating far above: the torque is free
    assert limited.plan.spm < free.plan.spm * (1 - 1e-3)
    failed = verify(free.plan, case)
    check = failed.check("crank_torque")
    assert not failed.passed and not check.passed and check.value > check.limit * 1.01
    assert time_optimal_bound(case, 720).spm >= limited.plan.spm


def test_check_lists_the_capacity(capsys):
    assert main(["check", str(CUP)]) == 0
    out = capsys.readouterr().out
    assert "PASS  forming force within the press's tonnage curve" in out
    assert "PASS  crank torque during the draw <= press.capacity.crank_torque_kNm" in out
