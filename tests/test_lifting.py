"""The lifted derivative functions (``planning.solver.lifting``) are the derivatives of the problem they
belong to: against CasADi's own differentiation of the composed problem, on the linkages' drive NLPs."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from planning.model.case_file import read_case
from planning.solver.search import prepare
from planning.solver.starts import published_starts

from .conftest import ROOT

AGREEMENT = 1e-9  # relative to each function's largest entry: the chain rule is exact, round-off remains


@pytest.mark.slow  # 4-7 s a case: the normal run keeps under 5 minutes (CI runs the slow tier)
@pytest.mark.parametrize("name", ["link-drive-side-panel", "knuckle-joint-coining"])
def test_lifted_derivatives_are_the_composed_problems(name):
    case = read_case(ROOT / "cases" / f"{name}.yaml")
    search = prepare(case, "free")  # the drive NLP: links, torque, every lifted quantity
    program = search.nlp.program
    assert isinstance(program.problem, ca.Function)  # lifted
    start = published_starts(case, search.draw_speed_range[1], None)[0]
    x = np.array([start[k] for k, _ in search.nlp.variables]) / search.scale
    p = np.concatenate([search.parameters, search.scale])
    rng = np.random.default_rng(7)
    lam_f, lam_g = 1.3, rng.normal(size=program.problem.size1_out(1))

    X, P = ca.MX.sym("x", x.size), ca.MX.sym("p", p.size)
    f, g = program.problem(X, P)
    reference = ca.Function(
        "reference",
        [X, P],
        [ca.gradient(f, X), ca.jacobian(g, X), ca.triu(ca.hessian(lam_f * f + ca.dot(lam_g, g), X)[0])],
    )
    grad_ref, jac_ref, hess_ref = (np.array(ca.densify(v)) for v in reference(x, p))
    _, grad = program.options["grad_f"](x, p)
    _, jac = program.options["jac_g"](x, p)
    hess = program.options["hess_lag"](x, p, lam_f, lam_g)
    for ours, theirs in ((grad, grad_ref), (jac, jac_ref), (hess, hess_ref)):
        ours = np.array(ca.densify(ours))
        scale = np.max(np.abs(theirs))
        assert scale > 0 and np.max(np.abs(ours - theirs)) <= AGREEMENT * scale
