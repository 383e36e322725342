"""The improved S-curve (paper Eqs. 10-21) against its own evaluated profile."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planning.model.laws import improved_scurve as sc
from planning.model.profile import Profile


def curve(v_s=1.0, J=30.0, T_a=0.1, T_d=0.13, T1=0.2, T10=0.3):
    return Profile(tuple(sc.segments(T_a, T_d, J, T1, T10)), 0.0, v_s)


def test_knot_values_of_eqs_11_and_12():
    v_s, J, Ta, Td = 1.0, 30.0, 0.1, 0.13
    k = curve(v_s, J, Ta, Td).knots()  # rows: t0, t1, ..., t10 (theta, omega, alpha)
    a = k[:, 2]
    v = k[:, 1]
    assert a[1] == 0 and a[2] == pytest.approx(J * Ta)  # a2 = J T2
    assert a[3] == pytest.approx(1.5 * J * Ta)  # a3 = 3/2 J T2 (Eq. 21)
    assert a[4] == pytest.approx(J * Ta) and a[5] == pytest.approx(0, abs=1e-12)
    assert a[6] == pytest.approx(-J * Td) and a[7] == pytest.approx(-1.5 * J * Td)  # Eq. 17
    assert a[8] == pytest.approx(-J * Td) and a[9] == pytest.approx(0, abs=1e-12)
    assert v[2] == pytest.approx(v_s + J * Ta**2 / 2)
    assert v[3] == pytest.approx(v_s + 11 / 6 * J * Ta**2)
    assert v[4] == pytest.approx(v_s + 19 / 6 * J * Ta**2)
    assert v[5] == pytest.approx(v_s + 11 / 3 * J * Ta**2)  # Eq. 13
    assert v[7] == pytest.approx(v[5] - 11 / 6 * J * Td**2)
    assert v[8] == pytest.approx(v[5] - 19 / 6 * J * Td**2)
    assert v[10] == pytest.approx(v_s + 11 / 3 * J * (Ta**2 - Td**2))  # Eq. 19


@settings(max_examples=60, deadline=None)
@given(
    v_s=st.floats(0.0, 3.0),
    J=st.floats(0.5, 500.0),
    Ta=st.floats(0.01, 0.5),
    Td=st.floats(0.01, 0.5),
    T1=st.floats(0.0, 1.0),
)
def test_relations_13_to_21_hold_for_any_curve(v_s, J, Ta, Td, T1):
    prof = curve(v_s, J, Ta, Td, T1, T1)
    k = prof.knots()
    v_max, v_e = k[5, 1], k[10, 1]
    tk = prof.knot_times
    t = np.concatenate([np.linspace(tk[i], tk[i + 1], 201) for i in range(len(tk) - 1)])
    a = prof.at_time(t)[2]  # 200 samples in every segment: a quadratic peak is off by < 1e-4
    a_max, a_min = a.max(), a.min()
    assert a_max == pytest.approx(sc.peak_accel(J, Ta), rel=1e-4)  # Eq. 21 (dense max)
    assert a_min == pytest.approx(-sc.peak_accel(J, Td), rel=1e-4)  # Eq. 17
    a_max, a_min = sc.peak_accel(J, Ta), -sc.peak_accel(J, Td)
    assert v_max == pytest.approx(v_s + sc.speed_change(J, Ta), rel=1e-12)  # Eq. 13
    assert sc.jerk_from_peak(a_max, Ta) == pytest.approx(J, rel=1e-12)  # Eq. 14
    assert sc.jerk_from_peak(-a_min, Td) == pytest.approx(J, rel=1e-12)
    assert sc.jerk_from_speed_change(a_max, v_max - v_s) == pytest.approx(J, rel=1e-9)
    assert sc.jerk_from_speed_change(a_min, v_max - v_e) == pytest.approx(J, rel=1e-9)
    assert sc.subsegment_time(v_max - v_s, a_max) == pytest.approx(Ta, rel=1e-9)  # Eq. 15
    assert sc.subsegment_time(v_max - v_e, -a_min) == pytest.approx(Td, rel=1e-9)  # Eq. 16
    assert a_min == pytest.approx(-Td / Ta * a_max, rel=1e-12)  # Eq. 17
    assert sc.constant_time(prof.duration, a_max, a_min, Ta) == pytest.approx(T1, abs=1e-9)  # Eq. 18
    assert prof.duration == pytest.approx(2 * T1 + 4 * Ta + 4 * Td)  # Eq. 20
    # angles of the halves (derived from Eq. 12)
    assert k[5, 0] - k[1, 0] == pytest.approx(sc.half_angle(v_s, J, Ta, True), rel=1e-12)
    assert k[9, 0] - k[5, 0] == pytest.approx(sc.half_angle(v_max, J, Td, False), rel=1e-12)


def test_acceleration_is_continuous_and_jerk_follows_eq_10():
    prof = curve()
    tk = prof.knot_times[1:-1]
    eps = 1e-7
    left, right = prof.at_time(tk - eps), prof.at_time(tk + eps)
    # across a knot a continuous quantity changes by (its slope) * 2 eps + O(eps^2); a jump would not
    assert np.max(np.abs(right[1] - left[1] - 2 * eps * prof.at_time(tk)[2])) < 1e-11  # speed
    assert np.max(np.abs(right[2] - left[2] - eps * (left[3] + right[3]))) < 1e-11  # acceleration
    J, Ta, Td = 30.0, 0.1, 0.13
    mid = prof.knot_times[:-1] + 0.5 * prof.durations
    jerk = prof.at_time(mid)[3]
    expected = [0, J, J / 2, -J / 2, -J, -J, -J / 2, J / 2, J, 0]  # Eq. 10 at the middle of each segment
    assert np.allclose(jerk, expected, atol=1e-9)
    del Ta, Td


def test_time_at_angle_inverts_the_profile():
    prof = curve()
    for t in np.linspace(0.01, prof.duration - 0.01, 23):
        th = float(prof.at_time(np.array([t]))[0][0])
        assert prof.time_at_angle(th) == pytest.approx(t, abs=1e-12)
