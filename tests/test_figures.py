"""The figures show every limit of the case, labelled by its field, and their legends never cover data."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from planning.model.case_file import read_case
from planning.reports.plots import laws_figure, plot_files, rendered, sweep_figure, tradeoff_figure
from planning.reports.report import result_dict, trajectory
from planning.solver import ahead as ahead_module
from tests.conftest import solved

CASES = sorted((Path(__file__).resolve().parents[1] / "cases").glob("*.yaml"))


def line_labels(fig: Figure) -> list[str]:
    return [a.get_label() for ax in fig.axes for a in ax.get_children() if isinstance(a, Line2D)]


def legend_overlaps(fig: Figure) -> list[str]:
    """Each legend whose box overlaps a panel's data area (in pixels, after drawing)."""
    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    found = []
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is None:
            continue
        box = legend.get_window_extent(renderer)
        for other in fig.axes:
            if other.get_label() == "<colorbar>":
                continue
            if box.overlaps(other.get_window_extent(renderer)):
                found.append(f"{ax.get_title() or ax.get_ylabel()!r} over {other.get_title() or other.get_ylabel()!r}")
    return found


def limits_of(case) -> list[str]:  # noqa: ANN001 - a Case
    """Every limit the case sets, by its dotted field."""
    fields = [f"limits.{k}" for k, v in case.limits.model_dump().items() if v is not None]
    if case.robots is not None:  # each robot's tool: the height it needs, on the slide's panel
        return [*(f"robots.{robot.name}" for robot in case.robots_on_path), *fields]
    return ["process.safety_height_mm", *fields]


@pytest.mark.parametrize("path", CASES, ids=lambda p: p.stem)
def test_every_limit_of_the_case_is_a_labelled_line(path):
    case = read_case(path)
    solution = solved(path)
    result = result_dict(solution, case)
    figures = plot_files(result, trajectory(solution, case), None)
    for name in ("motion_vs_angle.png", "motion_vs_time.png"):
        labels = line_labels(figures[name])
        missing = [f for f in limits_of(case) if not any(label.startswith(f) for label in labels)]
        assert not missing, f"{name}: {missing}"
        assert not legend_overlaps(figures[name]), name
        titles = " ".join(ax.get_title() for ax in figures[name].axes)
        assert "paper" not in titles  # no published profile given: no paper figure numbers
    assert ("drive.png" in figures) == (case.drive is not None)
    if case.drive is not None:
        labels = line_labels(figures["drive.png"])
        for field in ("drive.motor.peak_torque_Nm", "drive.motor.rated_torque_Nm"):
            assert any(label.startswith(field) for label in labels), field
        assert not legend_overlaps(figures["drive.png"])


def test_the_legend_check_sees_a_legend_over_the_data():
    """The overlap test can fail: a legend inside the axes is found."""
    fig = Figure()
    ax = fig.subplots()
    ax.plot([0, 1], [0, 1], label="data")
    ax.legend(loc="center")
    assert legend_overlaps(fig)


def _rows_1d(failed: tuple[int, ...]) -> list[dict]:
    return [
        {
            "process.transfer_time_s": t,
            "spm": "" if i in failed else 12 - t,
            "status": "x" if i in failed else "verified",
        }
        for i, t in enumerate(np.linspace(1, 3, 7))
    ]


def test_a_sweep_draws_failed_points_on_their_own_row():
    fig = sweep_figure(_rows_1d((5, 6)), ["process.transfer_time_s"], "sweep")
    curve, fails = fig.axes[:2]
    failed = [a for a in fails.get_lines() if a.get_label() == "no verified plan"]
    assert len(failed) == 1 and len(failed[0].get_xdata()) == 2
    assert all(len(a.get_xdata()) == 5 for a in curve.get_lines() if a.get_label() == "verified plan")
    assert not legend_overlaps(fig)


def test_a_heat_map_writes_each_cell_and_hatches_the_failed():
    rows = [
        {
            "a": a,
            "b": b,
            "spm": "" if (a, b) == (2.0, 2.0) else a + b,
            "status": "x" if (a, b) == (2.0, 2.0) else "verified",
        }
        for a in (1.0, 2.0)
        for b in (1.0, 2.0, 3.0)
    ]
    fig = sweep_figure(rows, ["a", "b"], "map")
    ax = fig.axes[0]
    assert sorted(t.get_text() for t in ax.texts) == ["2.00", "3.00", "3.00", "4.00", "5.00"]
    assert sum(1 for p in ax.patches if p.get_hatch()) == 1
    assert not legend_overlaps(fig)


def test_the_tradeoff_shows_the_saving_and_an_energy_axis_around_the_data(tmp_path):
    case = read_case(Path(__file__).resolve().parents[1] / "cases" / "wang2023-side-panel-drive.yaml")
    rows = [
        {
            "target_spm": s,
            "status": "verified",
            "rms_motor_torque_Nm": 15000 + 100 * s,
            "baseline_rms_motor_torque_Nm": 16000 + 100 * s,
            "peak_motor_torque_Nm": 60000,
            "baseline_peak_motor_torque_Nm": 61000,
            "energy_kJ": 1064 + s,
            "baseline_energy_kJ": 1080 + s,
        }
        for s in (5.0, 6.0, 7.0, 8.0)
    ]
    fig = tradeoff_figure(rows, case, "t")
    energy, saving = fig.axes[1], fig.axes[2]
    assert energy.get_ylim()[0] > 1000  # around 1064 ... 1088 kJ, not from 0
    saved = [a for a in saving.get_lines() if a.get_label() == "energy per stroke saved"][0]
    assert np.allclose(saved.get_ydata(), [100 * (1 - (1064 + s) / (1080 + s)) for s in (5, 6, 7, 8)])
    assert not legend_overlaps(fig)


def test_the_laws_overlay_keeps_its_legend_off_the_curves():
    theta = np.linspace(0, 360, 50)
    curves = {
        law: {"crank_angle_deg": theta, "crank_speed_rpm": 10 + k + np.sin(theta), "crank_accel_rad_s2": np.cos(theta)}
        for k, law in enumerate(("a", "b", "c"))
    }
    assert not legend_overlaps(laws_figure(curves, "laws"))


DRAWN_IN = "PRESSPLAN_TEST_DRAWN_IN"  # a file where the test's drawing notes the process that drew each figure


def _rendered_noting(name, result, traj, published, fmt):  # noqa: ANN001, ANN202 - as plots.rendered
    import os

    with open(os.environ[DRAWN_IN], "a") as f:
        f.write(f"{os.getpid()}\n")
    return rendered(name, result, traj, published, fmt)


@pytest.mark.skipif(not ahead_module._can_fork(), reason="no second core or no fork here")
@pytest.mark.parametrize("plot_format", ["png", "svg"])
def test_figures_drawn_side_by_side_are_the_files_drawn_in_turn(monkeypatch, tmp_path, plot_format):
    """``pressplan solve`` draws its figures in two forked workers at once (where a core is free): the same files,
    byte for byte (an SVG's date aside), as drawn one after another here, as a library caller gets them unless it
    asks (its process is not forked)."""
    import os
    import re

    import matplotlib

    from planning.reports import plots
    from planning.reports.outputs import Written
    from planning.reports.outputs.figures import OUTPUT

    path = next(p for p in CASES if p.stem == "wang2023-side-panel-drive")
    solution, case = solved(path), read_case(path)
    monkeypatch.setattr(plots, "rendered", _rendered_noting)
    monkeypatch.setattr(ahead_module, "core_free", lambda: True)  # as on a quiet machine
    monkeypatch.setenv(DRAWN_IN, str(tmp_path / "drawn_in"))
    monkeypatch.setitem(matplotlib.rcParams, "svg.hashsalt", "fixed")  # else an SVG's ids differ from run to run
    files = {}
    for way in ("side by side", "in turn"):
        written = Written(solution, case, {"plot_format": plot_format}, side_by_side_workers=way == "side by side")
        for name, write in OUTPUT.writers(written).items():
            write(tmp_path / name)
            files[way, name] = re.sub(rb"<dc:date>[^<]*</dc:date>", b"", (tmp_path / name).read_bytes())
    names = [f"{n}.{plot_format}" for n in ("motion_vs_time", "motion_vs_angle", "drive")]  # three: two workers
    assert sorted(name for way, name in files if way == "in turn") == sorted(names)
    for name in names:
        assert files["side by side", name] == files["in turn", name], name
    drawn_in = (tmp_path / "drawn_in").read_text().split()
    assert len(drawn_in) == 2 * len(names)
    assert str(os.getpid()) not in drawn_in[: len(names)] and set(drawn_in[len(names) :]) == {str(os.getpid())}
