"""The mechanism lifted out of an NLP's derivatives: its rows read the mechanism through symbols, and the
derivative functions IPOPT calls are put together by the chain rule.

An NLP samples the mechanism at crank angles ``theta_k(x)`` that depend on the decision variables ``x``
through the motion law, and its rows read quantities of the mechanism there: the slide's height ``h`` and
its derivatives ``h'``, ``h''`` with respect to the crank angle, and with a drive a linkage's inertia and
weight terms. Differentiated as one expression, every such quantity would be differentiated again for
every direction of the Hessian (each variable that moves a sample's angle): a linkage's closed form (a
chain of circle intersections, some hundred operations) would dominate the cost of an iteration. But each
quantity is a function of one number, its sample's crank angle, and its derivatives with respect to that
angle are further coefficients of the mechanism's series (``press.jets``). So the rows are built on
symbols ``eta`` (one per quantity and sample), and with ``E = d eta / d theta`` and
``F = d2 eta / d theta2`` (each entry with respect to its own sample's angle; from the series),
``J = d theta / dx`` (the motion law's closed form, by CasADi), the rows ``g(x, eta)``, the objective
``f(x, eta)`` and the Lagrangian ``L = lam_f f + lam_g^T g``::

    grad f = f_x + J^T E^T f_eta
    jac g  = g_x + g_eta E J
    hess L = L_xx + (L_x,eta E J + its transpose) + J^T (E^T L_eta,eta E + diag(sum_q L_eta_q F_q)) J
             + sum_k mu_k hess theta_k,    mu = E^T L_eta

(the sum over q runs over the quantities of one sample). Each piece is differentiated by CasADi where it
is cheap (the rows in ``x`` and ``eta``, the angles in ``x``), and the mechanism's expressions enter once
per sample. Then ``eta`` is replaced by the mechanism's expressions and the angles' symbols by
``theta_k(x)``: the functions IPOPT calls read ``x`` and the parameters only, and equal the derivatives of
the composed problem (``tests/test_lifting.py`` compares them with CasADi's own).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from press.jets import Jet

SERIES_ORDER = 4  # the mechanism's series in the NLPs: h, h', h'' and two more derivatives of each


@dataclass
class Lift:
    """The mechanism's quantities at an NLP's samples, lifted: ``angles`` the symbols of the sample angles
    [rad], ``angle_values`` their expressions in the decision variables and parameters; each quantity
    (:meth:`quantity`) a slice of the symbol ``symbols`` (room for :data:`CAPACITY` quantities) with its
    value and its first and second derivatives with respect to its sample's angle, expressions in
    ``angles`` and the parameters."""

    angles: Any
    angle_values: Any
    symbols: Any
    values: list[Any] = field(default_factory=list)
    first: list[Any] = field(default_factory=list)
    second: list[Any] = field(default_factory=list)

    @classmethod
    def at(cls, theta: Any) -> Lift:
        """Symbols for the sample angles ``theta`` (an SX or MX column)."""
        sym, n = type(theta), theta.shape[0]
        return cls(sym.sym("lifted_theta", n), theta, sym.sym("lifted", CAPACITY * n))

    def quantity(self, jet: Jet) -> Any:
        """The symbol of a quantity given as a jet in the angles (order 2 at least)."""
        if jet.order < 2:
            raise ValueError("a lifted quantity needs its first two derivatives")
        k, n = len(self.values), self.angles.shape[0]
        if k == CAPACITY:
            raise ValueError(f"at most {CAPACITY} lifted quantities")
        self.values.append(_column(jet.c[0], self.angles))
        self.first.append(_column(jet.c[1], self.angles))
        self.second.append(_column(jet.c[2], self.angles))
        return self.symbols[k * n : (k + 1) * n]

    def columns(self, coefficients: list[Any]) -> Any:
        """One coefficient of every quantity, stacked as :attr:`symbols` is (zeros where unused)."""
        n = self.angles.shape[0]
        unused = type(self.angles).zeros((CAPACITY - len(coefficients)) * n)
        return ca.vertcat(*coefficients, unused)


# a Hessian is symmetric: CasADi colours its columns for a symmetric matrix (star colouring), which needs far
# fewer directional sweeps than a general Jacobian's colouring where a row is dense (the period's, the motor's RMS
# integral): the optimal law's Hessian on a layout of 624 segments builds in 0.06 s instead of 2.7 s and
# evaluates in 13.5 ms instead of 92 ms (the same matrix)
SYMMETRIC = {"symmetric": True}
# ... on a large problem (the optimal law's: hundreds of variables) only: a law with halves (14 variables) or a
# pendulum's keeps CasADi's general colouring, which costs it nothing, and so its iterates: the multi-start of the
# laws with halves was checked on them (a random link drive's cold solve found no plan at one sweep point with the
# same derivatives evaluated in the other order: tests/test_best_of_law.py, link-drive-7)
LARGE_PROBLEM = 200
# a row of a constraint Jacobian that depends on more than this many variables is dense (the period's, the RMS
# torque's integral): CasADi colours a Jacobian's columns (forward sweeps) or its rows (adjoint sweeps), and a dense
# row with a dense column (a phase's step) needs as many sweeps as the smaller dimension; the dense rows apart (one
# adjoint sweep each) and the rest by columns, the optimal law's constraint Jacobian on 624 segments builds in
# 0.06 s instead of 1.5 s and evaluates in 7 ms instead of 32 ms
DENSE_ROW = 64
CAPACITY = 6  # lifted quantities per sample at most: the height and two derivatives, three link terms


def _column(value: Any, like: Any) -> Any:
    """``value`` as a column of ``like``'s length (a constant coefficient of a jet is a number)."""
    if isinstance(value, (ca.SX, ca.MX, ca.DM)) and value.shape[0] == like.shape[0]:
        return value
    return value * type(like).ones(like.shape[0])


def row_split_jacobian(rows: Any, x: Any) -> Any:
    """``d rows / d x``, its dense rows (:data:`DENSE_ROW`) differentiated apart from the others: the same matrix."""
    counts = np.diff(np.array(ca.jacobian_sparsity(rows, x).T.colind()))  # the variables of each row
    dense = np.flatnonzero(counts > DENSE_ROW)
    if dense.size == 0 or dense.size == counts.size:
        return ca.jacobian(rows, x)
    sparse = np.flatnonzero(counts <= DENSE_ROW)
    stacked = ca.vertcat(ca.jacobian(rows[sparse.tolist()], x), ca.jacobian(rows[dense.tolist()], x))
    return stacked[np.argsort(np.concatenate([sparse, dense])).tolist(), :]


def lifted_problem(problem: dict, lift: Lift) -> tuple[ca.Function, dict]:
    """The problem IPOPT solves (a function of ``x`` and ``p`` giving ``f`` and ``g``) and its derivative
    functions (``nlpsol``'s ``grad_f``, ``jac_g``, ``hess_lag`` options) by the chain rule of the module
    docstring. Each is the composition of three functions: the sample angles of ``x`` and ``p`` (the motion
    law), the mechanism's quantities and their derivatives at those angles, and the rows and their
    derivatives in ``x`` and the quantities; nothing is substituted into a large expression."""
    x, p, f, g = problem["x"], problem["p"], problem["f"], problem["g"]
    sym = type(x)
    n = lift.angles.shape[0]
    eta, e1, e2 = lift.symbols, sym.sym("first", CAPACITY * n), sym.sym("second", CAPACITY * n)
    E = ca.vertcat(*[ca.diag(e1[k * n : (k + 1) * n]) for k in range(CAPACITY)])  # (quantities x samples) x samples
    J = ca.jacobian(lift.angle_values, x)
    lam_f, lam_g = sym.sym("lam_f"), sym.sym("lam_g", g.shape[0])

    grad = ca.gradient(f, x) + ca.mtimes(J.T, ca.mtimes(E.T, ca.gradient(f, eta)))
    large = x.shape[0] > LARGE_PROBLEM
    by_rows, symmetric = (row_split_jacobian, SYMMETRIC) if large else (ca.jacobian, {})
    jac = by_rows(g, x) + ca.mtimes(by_rows(g, eta), ca.mtimes(E, J))
    lagrangian = lam_f * f + ca.dot(lam_g, g)
    l_x, l_eta = ca.gradient(lagrangian, x), ca.gradient(lagrangian, eta)
    cross = ca.mtimes(ca.jacobian(l_eta, x).T, ca.mtimes(E, J))
    curvature = ca.sum2(ca.reshape(l_eta * e2, n, -1))  # sum over the quantities of each sample
    inner = ca.mtimes(E.T, ca.mtimes(ca.jacobian(l_eta, eta, symmetric), E)) + ca.diag(curvature)
    weights = sym.sym("weights", n)
    angles_hessian = ca.hessian(ca.dot(weights, lift.angle_values), x)[0]
    angles_hessian = ca.substitute(angles_hessian, weights, ca.mtimes(E.T, l_eta))  # the law's part only
    hessian = ca.jacobian(l_x, x, symmetric) + cross + cross.T + ca.mtimes(J.T, ca.mtimes(inner, J)) + angles_hessian

    angles = ca.Function("lifted_angles", [x, p], [lift.angle_values])
    coefficients = [lift.columns(lift.values), lift.columns(lift.first), lift.columns(lift.second)]
    # the mechanism to the order each function needs (a function computes all its outputs at every call)
    mechanism = [ca.Function(f"lifted_mechanism_{k}", [lift.angles, p], coefficients[: k + 1]) for k in range(3)]
    rows = ca.Function("lifted_rows", [x, p, eta], [f, g])
    rows_jac = ca.Function("lifted_jac", [x, p, eta, e1], [g, jac])
    rows_hess = ca.Function("lifted_hess", [x, p, eta, e1, e2, lam_f, lam_g], [ca.triu(hessian)])

    X, P = ca.MX.sym("x", x.shape[0]), ca.MX.sym("p", p.shape[0])
    LF, LG = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", g.shape[0])
    at = angles(X, P)
    values = mechanism[0](at, P)  # one output: returned as it is
    nlp = ca.Function("nlp", [X, P], rows(X, P, values), ["x", "p"], ["f", "g"])
    if ca.depends_on(f, eta):
        values_1, first_1 = mechanism[1](at, P)
        gradient = ca.Function("lifted_grad", [x, p, eta, e1], [f, grad])(X, P, values_1, first_1)
    else:  # the period: no mechanism in it
        gradient = ca.Function("lifted_grad", [x, p], [f, ca.gradient(f, x)])(X, P)
    values_1, first_1 = mechanism[1](at, P)
    values_2, first_2, second_2 = mechanism[2](at, P)
    functions = {
        "grad_f": ca.Function("nlp_grad_f", [X, P], gradient, ["x", "p"], ["f", "grad_f_x"]),
        "jac_g": ca.Function("nlp_jac_g", [X, P], rows_jac(X, P, values_1, first_1), ["x", "p"], ["g", "jac_g_x"]),
        "hess_lag": ca.Function(
            "nlp_hess_l",
            [X, P, LF, LG],
            [rows_hess(X, P, values_2, first_2, second_2, LF, LG)],
            ["x", "p", "lam_f", "lam_g"],
            ["triu_hess_gamma_x_x"],
        ),
    }
    return nlp, functions
