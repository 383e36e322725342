"""The derivative functions IPOPT is given are the derivatives of the problem they belong to: the lifted ones
(``planning.solver.lifting``) against CasADi's own differentiation of the composed problem, on the linkages' drive
NLPs; an MX problem's against nlpsol's own."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from planning.model.case_file import read_case
from planning.model.free_profile import first_layout
from planning.model.laws.optimal import OptimalLaw
from planning.solver.free_nlp import free_nlp_for
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


def test_an_mx_problems_derivatives_are_nlpsols_own():
    """The optimal law's NLP (an MX problem, not lifted) is solved with its gradient and Hessian made by its
    oracle's factory (``ipopt._compiled``): they are the functions nlpsol derives itself, to the bit; its
    constraint Jacobian (rows split) agrees with nlpsol's to round-off."""
    case = read_case(ROOT / "cases" / "wang2023-side-panel.yaml")
    case = case.model_copy(update={"limits": case.limits.model_copy(update={"crank_jerk_rad_s3": 32.73})})
    case = case.with_law(OptimalLaw.name)
    nlp = free_nlp_for(case, first_layout(case.free_draw), drive=False)
    program = nlp.program
    assert isinstance(program.problem, dict) and isinstance(program.problem["x"], ca.MX)
    own = ca.nlpsol("reference", "ipopt", program.problem, {"print_time": False})
    rng = np.random.default_rng(11)
    x = rng.uniform(0.5, 1.5, size=program.problem["x"].shape[0])
    p = np.concatenate([nlp.layout.values(case), nlp.variable_scales(case)])
    lam_g = rng.normal(size=program.problem["g"].shape[0])
    solver = program._cold  # the solver IPOPT runs, with the functions it was given
    for name, args in (("nlp_grad_f", (x, p)), ("nlp_hess_l", (x, p, 1.3, lam_g))):
        ours, theirs = solver.get_function(name)(*args), own.get_function(name)(*args)
        ours, theirs = (
            (ours if isinstance(ours, (list, tuple)) else [ours]),
            (theirs if isinstance(theirs, (list, tuple)) else [theirs]),
        )
        for a, b in zip(ours, theirs, strict=True):
            assert a.sparsity() == b.sparsity() and np.array_equal(np.array(a.nonzeros()), np.array(b.nonzeros()))
    _, jac = solver.get_function("nlp_jac_g")(x, p)
    _, jac_ref = own.get_function("nlp_jac_g")(x, p)
    jac, jac_ref = np.array(ca.densify(jac)), np.array(ca.densify(jac_ref))
    assert np.max(np.abs(jac - jac_ref)) <= AGREEMENT * np.max(np.abs(jac_ref))
