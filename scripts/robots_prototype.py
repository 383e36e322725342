"""A prototype of issue 39's planning: the robots on their interference curves planned with the crank (the
improved S-curve's halves NLP), to measure the formulation before it is built into the project.

    python scripts/robots_prototype.py

Formulation: each robot's moves are its fastest (``press.robot``), so its position at a time ``tau`` after its
start is a known number and so is the height its tool needs there; its start ``s`` [s from theta3] is a decision
variable. Rows: at sample offsets ``tau_j`` of its occupancy where the tool needs height, the slide's height at
the crank angle of time ``s + tau_j`` (the NLP's closed-form angle at a time, clipped per segment) at least that
need; the loader reaches the die centre after the unloader leaves it; each robot's occupancy inside the cycle's
part before the draw. The safety-height and transfer-time rows are switched off (safety height 1 mm, transfer
0.01 s). The plan is then checked densely: the clearance at every 1 ms sample, both robots.

Not part of the project yet (no case field reads it); it prints what it finds.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import casadi as ca
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import planning.solver.halves_nlp as H  # noqa: E402
from planning.model.case_file import read_case  # noqa: E402
from planning.model.laws import get_law  # noqa: E402
from planning.solver.ipopt import NLPSolver  # noqa: E402
from planning.solver.nlp import CYCLE_OPTIONS, CycleNLP, Rows, add_limit_rows, sample_states  # noqa: E402
from planning.solver.optimize import solve  # noqa: E402
from planning.solver.parameters import ParameterLayout, time_limit  # noqa: E402
from press.robot import InterferenceCurve, MoveLimits, Robot  # noqa: E402

SAMPLES = 40  # rows per robot
TURNS = False


def crossings(robot: Robot) -> np.ndarray:
    """The offsets [s] from the robot's start at which its tool passes its curve's points (in and out): the
    rows there hold the need at the point itself (a step in the curve is not missed between samples)."""
    move, out = robot.move, []
    for x in robot.curve.positions_mm:
        if not 0.0 < x < robot.path_mm:
            continue
        for travelled, since in ((robot.path_mm - x, 0.0), (x, move.duration_s + robot.dwell_s)):
            lo, hi = 0.0, move.duration_s
            for _ in range(60):  # the move's distance is monotone in time: bisection
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if float(move.state(mid)[0]) < travelled else (lo, mid)
            out.append(since + hi)
    return np.array(out)


def robots(curve: InterferenceCurve) -> tuple[Robot, Robot]:
    """Two robots whose occupancies (in, 0.1 s dwell, out) take 1.0 s each: 2 s in turn, the paper's."""
    limits = MoveLimits(2500.0, 12500.0)  # T = L / v + v / a = 0.45 s for L = 625 mm
    return Robot("unloader", 625.0, limits, 0.1, curve), Robot("loader", 625.0, limits, 0.1, curve)


def build(unloader: Robot, loader: Robot):  # noqa: ANN201 - the patched _build
    def _build(law_name, formula, limit_ids, drive, rate, zone, links=(), peak=False, losses=False):  # noqa: ANN001, ANN202
        assert not drive and not rate and not peak
        law = get_law(law_name)
        die_exit = zone
        layout = ParameterLayout(formula, limit_ids, False, False, (), die_exit)
        variables = (
            H.VARIABLES
            + (H.EXIT_VARIABLES if die_exit else ())
            + (("unloader_start", "time"), ("loader_start", "time"))
        )
        c = H._cycle(law_name, layout, variables)
        rows = Rows()
        H._shape_rows(rows, c, law)
        published_rows, (omd, omu) = H._key_point_rows(rows, c)
        exit_speeds = H._exit_rows(rows, c, len(H.VARIABLES)) if die_exit else []
        states, times, draw_count = H._sampled(c, law, False)
        samples, torque, lift = sample_states(formula, layout, c.q, c.p_case, states, times, draw_count)
        p = c.params
        nlp = H._transcription(c, samples, (omd, omu), exit_speeds, False, False)
        refinable = add_limit_rows(rows, nlp, layout)
        # the robots' rows
        n = len(variables)
        s_u, s_l = c.x[n - 2] * c.p_scale[n - 2], c.x[n - 1] * c.p_scale[n - 1]
        geometry = layout.geometry(c.q)
        t_end = c.starts[c.n_before]
        for robot, start in ((unloader, s_u), (loader, s_l)):
            offsets = np.union1d(np.linspace(0.0, robot.occupancy_s, SAMPLES), crossings(robot))
            needs = robot.needed_height(offsets, 0.0, 1e9)
            keep = needs > 0
            theta = ca.vertcat(*[H._angle_at(start + float(tau), *c.before)[0] for tau in offsets[keep]])
            height = formula.jets(theta, geometry)[0]
            rows.add(
                f"{robot.name} clearance", (height - ca.DM(needs[keep])) / c.q["length_unit"], 0.0, np.inf, "robots"
            )
            rows.add(
                f"{robot.name} inside the cycle",
                ca.vertcat(start, t_end - start - robot.occupancy_s),
                0.0,
                np.inf,
                "robots",
            )
        if TURNS:  # the loader leaves its waiting point once the unloader is back at its own
            order = s_l - (s_u + unloader.occupancy_s)
        else:  # the loader reaches the die centre once the unloader has left it
            order = (s_l + loader.move.duration_s) - (s_u + unloader.move.duration_s + unloader.dwell_s)
        rows.add("the loader after the unloader", order, 0.0, np.inf, "robots")
        objective = p.period
        problem = {"x": c.x, "p": ca.vertcat(c.p_case, c.p_scale), "f": objective, "g": ca.vertcat(*rows.g)}
        program = NLPSolver(
            "robots_" + law_name.replace("-", "_") + ("_exit" if die_exit else ""), problem, CYCLE_OPTIONS, lift=lift
        )

        def scales(case):  # noqa: ANN001, ANN202
            base = (H.exit_variable_scales if die_exit else H.variable_scales)(case)
            return np.append(base, [base[H.VARIABLE_INDEX["closing_time"]]] * 2)

        def bounds(case, layout_, w2_lo, w2_hi, parameters):  # noqa: ANN001, ANN202
            lo, hi = (H.exit_variable_bounds if die_exit else H.variable_bounds)(
                case, layout_, w2_lo, w2_hi, parameters
            )
            return np.append(lo, [0.0, 0.0]), np.append(hi, [time_limit(case)] * 2)

        def complete(values):  # noqa: ANN001, ANN202
            values = H.complete_exit(values) if die_exit and "die_exit_time_0" not in values else dict(values)
            if "unloader_start" not in values:
                middle = 0.5 * (values["opening_time"] + values["closing_time"])  # about TDC
                values["unloader_start"] = middle - unloader.move.duration_s - unloader.dwell_s
                values["loader_start"] = middle - loader.move.duration_s
            return values

        denser = None if die_exit else (lambda: H._build(law_name, formula, limit_ids, drive, rate, True, links))
        return CycleNLP(
            program,
            *rows.bounds(),
            tuple(rows.blocks),
            layout,
            variables,
            scales,
            bounds,
            H.make_plan,
            published_rows,
            refinable,
            denser,
            complete,
        )

    return _build


def dense_clearance(solution, unloader: Robot, loader: Robot) -> dict[str, float]:  # noqa: ANN001
    """The least clearance of each robot at every sample of the dense verification [mm]."""
    samples = solution.evaluation.samples
    t, h = np.asarray(samples.t), np.asarray(samples.h)
    plan = solution.plan
    period = plan.period
    t3 = float(plan.key_times()[2])  # the NLP's times count from theta3
    out = {}
    for robot, key in ((unloader, "unloader_start"), (loader, "loader_start")):
        start = (plan.nlp_values[key] + t3) % period  # from theta3 to the plan's time from TDC
        need = robot.needed_height(t, start, period)
        clearance = h - need
        k = int(np.argmin(clearance))
        out[robot.name] = (float(clearance[k]), float(t[k]), start)
    return out


def main() -> None:
    case = read_case(ROOT / "cases" / "wang2023-side-panel.yaml")
    base = solve(case)
    print(f"safety-height model: {base.plan.spm:.3f} strokes/min (transfer {case.process.transfer_time_s} s)")
    relaxed = read_case(
        ROOT / "cases" / "wang2023-side-panel.yaml",
        {"process.safety_height_mm": 1.0, "process.transfer_time_s": 0.01, "planner.placement": "free"},
    )
    flat = InterferenceCurve((0.0, 625.0 - 1e-6), (700.0, 700.0))  # the tool needs 700 mm until it is out
    at_key = float(case.machine.height(math.radians(case.key_points.closing_deg)))  # the slide at theta1, theta4
    level = InterferenceCurve((0.0, 625.0 - 1e-6), (at_key, at_key))
    shaped = InterferenceCurve((0.0, 300.0, 450.0), (700.0, 700.0, 0.0))  # over the die to 300 mm, clear at 450
    global TURNS
    trials = (
        (f"flat at {at_key:.2f} mm (the slide at theta1 and theta4), in turns", level, True),
        ("flat at 700 mm, in turns", flat, True),
        ("flat at 700 mm", flat, False),
        ("over the die to 300 mm, clear at 450", shaped, False),
    )
    for name, curve, turns in trials:
        TURNS = turns
        unloader, loader = robots(curve)
        H._build = build(unloader, loader)
        H.halves_nlp.cache_clear()
        solution = solve(relaxed)
        clear = dense_clearance(solution, unloader, loader)
        print(
            f"robots, {name}: {solution.plan.spm:.3f} strokes/min; least clearance "
            + ", ".join(f"{r} {c:.6f} mm at {t:.3f} s (start {s:.3f} s)" for r, (c, t, s) in clear.items())
        )


if __name__ == "__main__":
    main()
