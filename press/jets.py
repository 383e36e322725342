"""Taylor jets in the crank angle: a value and its derivatives, carried through arithmetic.

A linkage's slide height is a chain of closed forms (circle intersections, square roots); its derivatives
with respect to the crank angle follow from the same chain by the rules of differentiation, applied here
to every operation at once (forward-mode differentiation, truncated after the jet's order). A jet of
order n holds ``(f, f', ..., f^(n))`` of one quantity; every coefficient is a number, a numpy array or a
CasADi symbol (``press.backend``), so one formula gives the numpy values of the verification and the CasADi
expressions of the NLPs. The verification needs three derivatives of the height (the slide's jerk); the
NLPs four (the second derivative of the slide's acceleration with respect to the crank angle, which their
Hessian takes from the jet: ``planning.solver.lifting``).

Rules, with ``u`` a jet and primes its derivatives:

- product (Leibniz): ``(uv)^(k) = sum_i C(k, i) u^(i) v^(k - i)``;
- a function of one jet (Faa di Bruno, to fourth order): ``f(u)' = f1 u'``,
  ``f(u)'' = f2 u'^2 + f1 u''``, ``f(u)''' = f3 u'^3 + 3 f2 u' u'' + f1 u'''``,
  ``f(u)'''' = f4 u'^4 + 6 f3 u'^2 u'' + f2 (3 u''^2 + 4 u' u''') + f1 u''''`` with ``fk`` the k-th
  derivative of ``f`` at ``u``; the square root, the reciprocal, sine and cosine are such functions.

A constant (a jet of order 0) combines with a jet of any order; two jets of different orders give the
lower order.
"""

from __future__ import annotations

from math import comb
from typing import Any

from press.backend import math_module

ORDER = 3  # derivatives carried by default (the verification's: the slide's jerk)
MAX_ORDER = 4  # the highest order the compositions know


class Jet:
    """``(f, f', ..., f^(n))`` of one quantity with respect to the crank angle [rad]; ``n`` is :attr:`order`."""

    __slots__ = ("c",)

    def __init__(self, *c: Any):
        self.c = c

    @classmethod
    def angle(cls, theta: Any, order: int = ORDER) -> Jet:
        """The crank angle itself: ``(theta, 1, 0, ...)`` to ``order``."""
        if not 0 < order <= MAX_ORDER:
            raise ValueError(f"a jet's order must lie in 1 ... {MAX_ORDER}")
        return cls(theta, 1.0, *([0.0] * (order - 1)))

    @property
    def value(self) -> Any:
        return self.c[0]

    @property
    def order(self) -> int:
        return len(self.c) - 1

    def derivative(self) -> Jet:
        """The jet of ``f'``: one order less."""
        return Jet(*self.c[1:])

    def __add__(self, other: Any) -> Jet:
        a, b = _aligned(self, _jet(other))
        return Jet(*(x + y for x, y in zip(a, b, strict=True)))

    __radd__ = __add__

    def __neg__(self) -> Jet:
        return Jet(*(-a for a in self.c))

    def __sub__(self, other: Any) -> Jet:
        return self + (-_jet(other))

    def __rsub__(self, other: Any) -> Jet:
        return _jet(other) - self

    def __mul__(self, other: Any) -> Jet:
        if not isinstance(other, Jet) or other.order == 0:  # a constant factor
            k = other.c[0] if isinstance(other, Jet) else other
            return Jet(*(a * k for a in self.c))
        if self.order == 0:
            return other * self
        n = min(self.order, other.order)
        u, v = self.c, other.c
        return Jet(*(sum(comb(k, i) * u[i] * v[k - i] for i in range(k + 1)) for k in range(n + 1)))

    __rmul__ = __mul__

    def __truediv__(self, other: Any) -> Jet:
        if not isinstance(other, Jet) or other.order == 0:
            k = other.c[0] if isinstance(other, Jet) else other
            return Jet(*(a / k for a in self.c))
        return self * other.reciprocal()

    def __rtruediv__(self, other: Any) -> Jet:
        return _jet(other) * self.reciprocal()

    def square(self) -> Jet:
        return self * self

    def compose(self, *f: Any) -> Jet:
        """``f(self)`` for a function with value ``f[0]`` and derivatives ``f[1]``, ... at the value (as
        many as the jet's order)."""
        u = self.c
        out = [f[0]]
        if self.order >= 1:
            out.append(f[1] * u[1])
        if self.order >= 2:
            out.append(f[2] * u[1] ** 2 + f[1] * u[2])
        if self.order >= 3:
            out.append(f[3] * u[1] ** 3 + 3 * f[2] * u[1] * u[2] + f[1] * u[3])
        if self.order >= 4:
            out.append(
                f[4] * u[1] ** 4 + 6 * f[3] * u[1] ** 2 * u[2] + f[2] * (3 * u[2] ** 2 + 4 * u[1] * u[3]) + f[1] * u[4]
            )
        return Jet(*out)

    def reciprocal(self) -> Jet:
        r = 1.0 / self.c[0]
        return self.compose(r, -(r**2), 2 * r**3, -6 * r**4, 24 * r**5)

    def sqrt(self) -> Jet:
        m = math_module(self.c[0])
        s = m.sqrt(self.c[0])
        r = 1.0 / s
        return self.compose(s, 0.5 * r, -0.25 * r**3, 0.375 * r**5, -0.9375 * r**7)

    def sin(self) -> Jet:
        m = math_module(self.c[0])
        s, c = m.sin(self.c[0]), m.cos(self.c[0])
        return self.compose(s, c, -s, -c, s)

    def cos(self) -> Jet:
        m = math_module(self.c[0])
        s, c = m.sin(self.c[0]), m.cos(self.c[0])
        return self.compose(c, -s, -c, s, c)


def _jet(value: Any) -> Jet:
    return value if isinstance(value, Jet) else Jet(value)


def _aligned(a: Jet, b: Jet) -> tuple[tuple, tuple]:
    """The coefficients of two jets at a common order: a constant padded with zeros, else the lower order."""
    if a.order == 0:
        return (a.c[0], *([0.0] * b.order)), b.c
    if b.order == 0:
        return a.c, (b.c[0], *([0.0] * a.order))
    n = min(a.order, b.order) + 1
    return a.c[:n], b.c[:n]


class Point:
    """A point of a linkage in the plane, two jets: ``x`` and ``y`` [mm] (y up)."""

    __slots__ = ("x", "y")

    def __init__(self, x: Any, y: Any):
        self.x, self.y = _jet(x), _jet(y)

    def __add__(self, other: Point) -> Point:
        return Point(self.x + other.x, self.y + other.y)

    def __sub__(self, other: Point) -> Point:
        return Point(self.x - other.x, self.y - other.y)

    def scaled(self, k: Any) -> Point:
        return Point(self.x * k, self.y * k)

    def turned(self, cos_a: float, sin_a: float) -> Point:
        """The vector turned by a constant angle (its cosine and sine)."""
        return Point(self.x * cos_a - self.y * sin_a, self.x * sin_a + self.y * cos_a)

    def perpendicular(self) -> Point:
        """The vector turned a quarter turn counter-clockwise."""
        return Point(-self.y, self.x)

    def dot(self, other: Point) -> Jet:
        return self.x * other.x + self.y * other.y


def circle_intersection(p: Point, r1: Any, q: Point, r2: Any, side: float) -> tuple[Point, Jet]:
    """The point ``r1`` from ``p`` and ``r2`` from ``q``, on the ``side`` (+1: left of p -> q, -1: right),
    and the jet of the square root's argument (negative where the two circles do not meet: the linkage
    cannot assemble there). With ``D = q - p``: ``p + k D + side sqrt(r1^2 / |D|^2 - k^2) perp(D)``,
    ``k = (r1^2 - r2^2 + |D|^2) / (2 |D|^2)``."""
    d = q - p
    dd = d.dot(d)
    k = (dd + (r1**2 - r2**2)) / (dd * 2.0)
    room = r1**2 / dd - k * k
    return p + d.scaled(k) + d.perpendicular().scaled(room.sqrt() * side), room
