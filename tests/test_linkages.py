"""Link-drive and knuckle-joint presses against independent kinematics packages (mechpress, presslink), their
drive terms against closed forms, and their bad geometry refused."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from mechpress.ld import LD
from presslink.kj_modular import ModularKnuckleJoint

from planning.cli import main
from planning.model.case_file import load_yaml, read_case
from press.crank_slider import CrankSlider
from press.dynamics import GRAVITY, DriveModel, LinkMass, crank_torque, link_jets, link_terms
from press.jets import Jet
from press.linkage import KnuckleJoint, LinkageError, LinkDrive

from .conftest import ROOT

LINK_DRIVE_CASE = ROOT / "cases" / "link-drive-side-panel.yaml"
KNUCKLE_JOINT_CASE = ROOT / "cases" / "knuckle-joint-coining.yaml"
HEIGHT_TOL_MM = 1e-3  # the acceptance: 1e-6 m at every angle of the oracle's grid
# mechpress's example link drive (its docstring's numbers) [m, rad]; presslink's knuckle joint [mm]
MECHPRESS_EXAMPLE = {
    "a": 0.260,
    "b": 0.8,
    "c": 0.9,
    "d": 1.175,
    "f": 0.375,
    "tht": 2.33923,
    "g": 1.175,
    "h": 0.0,
    "m": 1.175,
}
PRESSLINK_EXAMPLE = {"a": 187.5, "b": 920.0, "c": 830.0, "d": 730.0, "e": 737.5, "g": 830.0, "h": 0.0}
STILL = DriveModel(0.0, 0.0, 0.0, 1.0, 1.0, 0.0, (), (), 0.0, math.pi)  # no masses, no losses


def link_drive_of(case_path: Path) -> tuple[LinkDrive, dict]:
    """The shipped case's mechanism and its dimensions in mechpress's letters [m, rad]."""
    p = load_yaml(case_path.read_text())["press"]["link_drive"]
    letters = {
        "a": p["crank_radius_mm"],
        "b": p["ternary_rocker_side_mm"],
        "c": p["rocker_mm"],
        "d": p["rocker_pivot_x_mm"],
        "f": p["rocker_pivot_y_mm"],
        "g": p["rod_length_mm"],
        "h": p["slide_offset_mm"],
        "m": p["ternary_rod_side_mm"],
    }
    letters = {k: v / 1e3 for k, v in letters.items()} | {"tht": math.radians(p["ternary_angle_deg"])}
    return read_case(case_path).machine, letters


def link_drive(letters: dict) -> LinkDrive:
    mm = {k: v * 1e3 for k, v in letters.items() if k != "tht"}
    return LinkDrive(mm["a"], mm["b"], mm["c"], mm["d"], mm["f"], letters["tht"], mm["m"], mm["g"], mm["h"])


def mechpress_of(letters: dict, force_N: float = 1.0, rated_distance_m: float = 0.0) -> LD:
    x = letters
    return LD(x["a"], x["b"], x["c"], x["d"], x["f"], x["tht"], x["g"], x["h"], x["m"], force_N, rated_distance_m)


def slide_position_mm(mechanism, phi: np.ndarray) -> np.ndarray:
    """The slide's position [mm, up] from the crank centre at the oracles' crank angles ``phi`` [rad]."""
    return mechanism.height(phi - mechanism.tdc_own_angle) + mechanism.geometry[-1]


def link_drive_cases() -> list[tuple[str, LinkDrive, dict]]:
    shipped, letters = link_drive_of(LINK_DRIVE_CASE)
    return [("mechpress example", link_drive(MECHPRESS_EXAMPLE), MECHPRESS_EXAMPLE), ("shipped", shipped, letters)]


@pytest.mark.parametrize("name, mechanism, letters", link_drive_cases(), ids=lambda x: x if isinstance(x, str) else "")
def test_link_drive_heights_agree_with_mechpress(name, mechanism, letters):
    """Every one of LD's 3601 angles: the slide's position (LD's k counts down from the crank centre)."""
    oracle = mechpress_of(letters)
    phi = np.array(oracle.get_th2_decideg_lst())
    theirs = -np.array(oracle.k_lst) * 1e3
    assert len(phi) == 3601
    assert np.max(np.abs(slide_position_mm(mechanism, phi) - theirs)) <= HEIGHT_TOL_MM
    assert mechanism.stroke == pytest.approx(oracle.get_stroke() * 1e3, abs=HEIGHT_TOL_MM)
    tdc_deg = math.degrees(mechanism.tdc_own_angle)
    bdc_deg = math.degrees(mechanism.tdc_own_angle + mechanism.bdc_angle) % 360
    assert abs(tdc_deg - oracle.get_th2_tdc()) <= 0.05 and abs(bdc_deg - oracle.get_th2_bdc()) <= 0.05  # its grid
    if name == "mechpress example":  # the reference figures
        assert oracle.get_stroke() == pytest.approx(1.00573, abs=1e-5)
        assert (round(oracle.get_th2_tdc(), 1), round(oracle.get_th2_bdc(), 1)) == (49.2, 270.0)


@pytest.mark.parametrize("name, mechanism, letters", link_drive_cases(), ids=lambda x: x if isinstance(x, str) else "")
def test_link_drive_slope_agrees_with_mechpress_velocity_and_its_finite_differences(name, mechanism, letters):
    """dh/dtheta against LD's own velocity analysis (at 1 rad/s, k counts down) and against a five-point
    finite difference of LD's positions on its 0.1 deg grid (error of order step^4: far below 1e-6 of the
    largest slope)."""
    oracle = mechpress_of(letters)
    phi = np.array(oracle.get_th2_decideg_lst())
    slope = mechanism.derivatives(phi - mechanism.tdc_own_angle)[0]  # [mm/rad]
    scale = float(np.max(np.abs(slope)))
    velocity = -np.array(oracle.get_vel_lst(1.0)) * 1e3
    assert np.max(np.abs(slope - velocity)) <= 1e-6 * scale
    k = -np.array(oracle.k_lst[:-1]) * 1e3  # one turn, the last angle repeats the first
    step = phi[1] - phi[0]
    five_point = (np.roll(k, 2) - 8 * np.roll(k, 1) + 8 * np.roll(k, -1) - np.roll(k, -2)) / (12 * step)
    assert np.max(np.abs(slope[:-1] - five_point)) <= 1e-6 * scale


@pytest.mark.parametrize("name, mechanism, letters", link_drive_cases(), ids=lambda x: x if isinstance(x, str) else "")
def test_quasi_static_torque_is_force_times_slope_and_meets_mechpress_rated_torque(name, mechanism, letters):
    """A constant force F on the slide, no masses: T_c = F dh/dtheta (virtual work). At the rated distance
    above BDC going down, LD.get_eg_torque() reads its velocity at the grid angle before the crossing: the two
    differ by at most F |d2h/dtheta2| times the 0.1 deg step."""
    force = 8.0e6  # [N] 8000 kN
    rated = 0.013  # [m] above BDC
    theta = np.linspace(0.0, 2 * math.pi, 721)
    _, d1, d2, _ = mechanism.jets(theta)
    torque = crank_torque(1.0, 0.0, d1, d2, force, STILL)
    np.testing.assert_allclose(torque, -force * d1 * 1e-3, rtol=1e-12, atol=1e-9)
    down = mechanism.angles_at_height(rated * 1e3)[0]
    _, d1, d2, _ = mechanism.jets(down)
    ours = float(crank_torque(1.0, 0.0, d1, d2, force, STILL))
    theirs = mechpress_of(letters, force, rated).get_eg_torque()
    grid_step = math.radians(0.1)
    curvature = np.max(np.abs(mechanism.derivatives(down + np.linspace(-grid_step, grid_step, 21))[1])) * 1e-3
    assert ours > 0 and abs(ours - theirs) <= force * curvature * grid_step
    assert abs(ours - theirs) <= 0.01 * ours  # within 1 %: the grid's offset at this distance


def presslink_of(p: dict) -> ModularKnuckleJoint:
    return ModularKnuckleJoint(p["a"], p["b"], p["c"], p["d"], p["e"], p["c"], p["g"], p["h"], 0, 20, 3)


def knuckle_joint_cases() -> list[tuple[str, KnuckleJoint, dict]]:
    p = load_yaml(KNUCKLE_JOINT_CASE.read_text())["press"]["knuckle_joint"]
    letters = {
        "a": p["crank_radius_mm"],
        "b": p["rod_length_mm"],
        "c": p["rocker_mm"],
        "d": p["rocker_pivot_x_mm"],
        "e": p["rocker_pivot_y_mm"],
        "g": p["main_rod_mm"],
        "h": p["slide_offset_mm"],
    }
    x = PRESSLINK_EXAMPLE
    example = KnuckleJoint(x["a"], x["b"], x["c"], x["d"], x["e"], x["g"], x["h"])
    return [("presslink example", example, x), ("shipped", read_case(KNUCKLE_JOINT_CASE).machine, letters)]


@pytest.mark.parametrize(
    "name, mechanism, letters", knuckle_joint_cases(), ids=lambda x: x if isinstance(x, str) else ""
)
def test_knuckle_joint_heights_agree_with_presslink(name, mechanism, letters):
    """Every one of ModularKnuckleJoint's 360 angles (root_op 3, f = c): its slide distance counts from the
    rocker's pivot height."""
    oracle = presslink_of(letters)
    phi = np.radians(np.array(oracle.get_th2d_lst(), dtype=float))
    theirs = np.array(oracle.get_d_lst()) + letters["e"]
    assert len(phi) == 360
    assert np.max(np.abs(slide_position_mm(mechanism, phi) - theirs)) <= HEIGHT_TOL_MM
    if name == "presslink example":
        assert mechanism.stroke == pytest.approx(181.63, abs=0.005)


def test_a_knuckle_joints_dwell_is_passed_first_going_down_and_last_going_up():
    """presslink's example wobbles by 0.014 mm near BDC (two lowest points): a height inside the wobble is
    reached first on the way down and left last on the way up, and the crossings hold the height."""
    x = PRESSLINK_EXAMPLE
    kj = KnuckleJoint(x["a"], x["b"], x["c"], x["d"], x["e"], x["g"], x["h"])
    theta = np.linspace(0.0, 2 * math.pi, 36001)
    h = kj.height(theta)
    target = 0.005
    down, up = kj.angles_at_height(target)
    assert h[theta < down].min() > target - 1e-9 and h[theta > up].min() > target - 1e-9
    assert np.any(h[(theta > down) & (theta < up)] > target)  # it rises above the target between the two
    assert float(kj.height(down)) == pytest.approx(target, abs=1e-9)
    assert float(kj.height(up)) == pytest.approx(target, abs=1e-9)


@pytest.mark.parametrize("mechanism", [m for _, m, _ in link_drive_cases() + knuckle_joint_cases()])
def test_the_series_derivatives_are_the_heights_derivatives(mechanism):
    """The jets' derivatives (forward-mode, ``press.jets``) against central differences of the height, and
    the fourth coefficient of the order-4 series (the NLPs') against a difference of the third."""
    theta = np.linspace(0.1, 2 * math.pi - 0.1, 97)
    step = 1e-4
    np.testing.assert_array_equal(
        np.array(mechanism.jets(theta)), np.array(mechanism.formula.series(theta, mechanism.geometry, 3).c)
    )
    series = mechanism.formula.series
    g = mechanism.geometry

    def coefficient(k: int, at: np.ndarray) -> np.ndarray:
        return series(at, g, 4).c[k]

    for k in range(4):
        fd = (coefficient(k, theta + step) - coefficient(k, theta - step)) / (2 * step)
        scale = np.max(np.abs(coefficient(k + 1, theta)))
        assert np.max(np.abs(fd - coefficient(k + 1, theta))) <= 1e-6 * scale, k


def test_a_rigid_rod_is_the_two_point_rod_plus_its_crank_pin_weight():
    """The crank-slider's rod as a rigid link of mass m, centre of gravity a from the crank pin and inertia
    m a (L - a) about it (``drive.links``) is dynamically the two point masses of ``rod_split`` (m b / L at the
    wrist pin, m a / L at the crank pin): the crank torque equals the lumped model's plus the weight of the
    crank-pin mass, which the lumped model leaves out (a balanced crank)."""
    R, L, mass, a = 450.0, 1200.0, 8000.0, 480.0
    press = CrankSlider(R, L)
    theta = np.linspace(0.0, 2 * math.pi, 181)
    omega, alpha = 1.3, 0.7
    _, d1, d2, _ = press.jets(theta)
    rigid = (LinkMass("rod", mass, a, 0.0, mass * (a * 1e-3) * ((L - a) * 1e-3)),)
    links = link_terms(press.frames(theta), rigid)
    slide_share, crank_inertia = press.rod_split(mass, a)
    lumped = DriveModel(slide_share, crank_inertia, 0.0, 1.0, 1.0, 0.0, (), (), 0.0, math.pi)
    torque_rigid = crank_torque(omega, alpha, d1, d2, 0.0, STILL, links)
    crank_pin_weight = (mass - slide_share) * GRAVITY * (-R * 1e-3 * np.sin(theta))  # m_A g dy_A/dtheta
    torque_lumped = crank_torque(omega, alpha, d1, d2, 0.0, lumped)  # the wrist-pin share's weight included
    scale = float(np.max(np.abs(torque_rigid)))
    assert np.max(np.abs(torque_rigid - (torque_lumped + crank_pin_weight))) <= 1e-9 * scale


@pytest.mark.parametrize("path", [LINK_DRIVE_CASE, KNUCKLE_JOINT_CASE], ids=lambda p: p.stem)
def test_link_terms_are_the_kinetic_and_potential_energies_derivatives(path):
    """J_links(theta) is twice the links' kinetic energy at 1 rad/s; its derivative (the jets') matches a
    difference of J_links, and the weight term sum m g y_G' a difference of the links' potential energy."""
    case = read_case(path)
    mechanism, links = case.machine, case.drive_model.links
    theta = np.linspace(0.2, 2 * math.pi - 0.2, 61)
    step = 1e-5

    def energies(at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        frames = mechanism.frames(at)
        J, _ = link_jets(frames, links)
        potential = np.zeros_like(at)
        for link in links:
            first, second, length = frames[link.name]
            axis = (second - first).scaled(1.0 / length)
            cg = first + axis.scaled(link.along) + axis.perpendicular().scaled(link.across)
            potential = potential + link.mass * GRAVITY * cg.y.value * 1e-3
        return J.value, potential

    J, dJ, weight = link_terms(mechanism.frames(theta), links)
    (J_hi, V_hi), (J_lo, V_lo) = energies(theta + step), energies(theta - step)
    assert np.all(J > 0)
    np.testing.assert_allclose(dJ, (J_hi - J_lo) / (2 * step), rtol=0, atol=1e-6 * np.max(np.abs(dJ)))
    np.testing.assert_allclose(weight, (V_hi - V_lo) / (2 * step), rtol=0, atol=1e-6 * np.max(np.abs(weight)))


def test_a_jet_composes_to_fourth_order():
    """Faa di Bruno to fourth order: sqrt(1 + sin^2 x) against its Taylor coefficients by finite differences."""
    x = np.linspace(-1.0, 1.0, 11)
    jet = (Jet.angle(x, 4).sin().square() + 1.0).sqrt()

    def f(t):
        return np.sqrt(1 + np.sin(t) ** 2)

    step = 3e-3  # truncation about 1e-4, round-off about 1e-5 of these values (up to 7)
    stencil = [f(x + k * step) for k in (-2, -1, 0, 1, 2)]
    fourth = (stencil[0] - 4 * stencil[1] + 6 * stencil[2] - 4 * stencil[3] + stencil[4]) / step**4
    np.testing.assert_allclose(jet.c[4], fourth, atol=5e-4)


@pytest.mark.parametrize(
    "case_path, edits, field",
    [
        (LINK_DRIVE_CASE, {"rocker_mm: 810": "rocker_mm: 200"}, "press.link_drive.rocker_mm"),  # cannot close
        (LINK_DRIVE_CASE, {"rod_length_mm: 1060": "rod_length_mm: -1060"}, "press.link_drive.rod_length_mm"),
        (
            LINK_DRIVE_CASE,
            {"rocker_pivot_x_mm: 1060": "rocker_pivot_x_mm: 100", "rocker_pivot_y_mm: 340": "rocker_pivot_y_mm: 100"},
            "press.link_drive.rocker_pivot_x_mm",
        ),  # the pivot inside the crank circle
        (LINK_DRIVE_CASE, {"rocker_pivot_x_mm: 1060": "rocker_pivot_x_mm: 100"}, "press.link_drive"),  # turns back
        (KNUCKLE_JOINT_CASE, {"main_rod_mm: 910": "main_rod_mm: 0"}, "press.knuckle_joint.main_rod_mm"),
        (KNUCKLE_JOINT_CASE, {"main_rod_mm: 910": "main_rod_mm: 300"}, "press.knuckle_joint.main_rod_mm"),
        (KNUCKLE_JOINT_CASE, {"rocker_mm: 910": "rocker_mm: 2000"}, "press.knuckle_joint.rocker_mm"),
        (KNUCKLE_JOINT_CASE, {"slide_offset_mm: 0 ": "slide_offset_mm: 700 "}, "press.knuckle_joint"),
        (LINK_DRIVE_CASE, {"mechanism: link-drive": "mechanism: crank-slider"}, "press.crank_radius_mm"),
        (LINK_DRIVE_CASE, {"  links:": "  rod_mass_kg: 100\n  links:"}, "drive.rod_mass_kg"),
        (KNUCKLE_JOINT_CASE, {"    rocker: {": "    ternary: {"}, "drive.links.ternary"),
    ],
)
def test_bad_geometry_is_exit_2_naming_the_field_and_writes_nothing(case_path, edits, field, tmp_path, capsys):
    text = case_path.read_text()
    for old, new in edits.items():
        assert old in text
        text = text.replace(old, new, 1)
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    out = tmp_path / "out"
    assert main(["solve", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f": {field}" in err[0] and "Traceback" not in err[0]
    assert not out.exists()


def test_a_linkage_that_cannot_close_names_the_crank_angle():
    with pytest.raises(LinkageError, match=r"cannot close at crank angle \d+\.\d deg"):
        LinkDrive(235.0, 720.0, 200.0, 1060.0, 340.0, math.radians(134), 1060.0, 1060.0)


def test_check_prints_the_dead_centres_in_the_mechanisms_own_angle(capsys):
    assert main(["check", str(LINK_DRIVE_CASE)]) == 0
    text = capsys.readouterr().out
    assert "link-drive: stroke 918.25" in text and "TDC at 48.83 deg" in text and "BDC at 269.72 deg" in text
    assert "goes down for 220.89 deg (61.4 % of the turn)" in text
