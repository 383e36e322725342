"""Every tolerance of pressplan, in one place: each with its unit and why it has its value.

The numerical contract the README states is here: what the dense verification allows, how close counts as
binding, where round-off ends and a real difference begins, what the solver is asked to reach. Every layer
reads this module (the machine's geometry too); it imports nothing of the project's, and nothing else in
``planning/`` or ``press/`` writes a tolerance as a literal (``tests/test_architecture.py`` holds it).

Three kinds:

- **verification** tolerances: how far a measured figure may pass its limit and still pass (the contract);
- **round-off** allowances: two numbers this close are the same number (a knot found twice, an angle
  computed two ways); far below anything a press could feel;
- **solver** settings and margins: what IPOPT is asked to reach and how far inside its limits an NLP plans
  (so that the dense check, which sees between the NLP's samples, passes).
"""

from __future__ import annotations

# --- verification: the numerical contract --------------------------------------------------------------------

LIMIT_REL_TOL = 1e-6  # relative: a limit's dense check passes within this share of the limit (six digits:
# more than any press's data has, far above the round-off of evaluating the closed forms)
CAP_SHARE = 1e-3  # relative: a limit this close to its value where a draw falls below its slide speed caps it
DRAW_SPEED_BAND = 1e-3  # relative: a draw at constant slide speed holds it within 0.1 % (the reports' band)
HOLD_STILL_MM = 1e-3  # [mm] the slide stands at its hold height within a micrometre (the hold's check)
HOLD_STILL_RAD_S = 1e-9  # [rad/s] the crank stands in a hold (a cam's standstill is still to round-off)
TIME_TOL_S = 1e-6  # [s] a time limit (the robot's window, a target cycle time): a microsecond
ANGLE_TOL_RAD = 1e-6  # [rad] the key angles reached and the cycle closed (0.06 millidegree, far below a
# resolver's count; the time-at-angle search converges to 1e-14)
SPEED_TOL_RAD_S = 1e-9  # [rad/s] the speed continuous at a knot and constant along the draw: the closed
# forms give these exactly up to round-off (1e-12 relative of speeds near 1 rad/s)
ACCEL_CLOSE_TOL_RAD_S2 = 1e-6  # [rad/s^2] the acceleration at the cycle's two ends (a sum over every
# segment's jerk: its round-off is larger than a single evaluation's)
CONTINUITY_TOL = 1e-9  # [rad/s, rad/s^2] a jump allowed at a knot beyond the O(eps^2) remainder
ENERGY_REL_TOL = 1e-6  # relative to the larger of the forming work and integral |T_c omega| dt: the energy
# balance (the quadrature is exact to about 1e-12 relative)
KNOT_PROBE_S = 1e-7  # [s] the continuity check looks this far either side of a knot (at most a quarter of
# the shorter neighbouring segment): short enough that the O(eps^2) remainder is round-off
ROUND_OFF_REL = 1e-14  # relative: round-off of a closed-form value near the largest term (a few ulps)
CAM_POINT_GAP_DEG = 1e-2  # [deg of the master] two of a law's segment ends this close are one point of a cam:
# a quintic over a shorter interval loses its higher coefficients to round-off (they divide by its width^5)
CAM_END_TOL = 1e-9  # [deg, deg/deg, deg/deg^2] a cam's position, slope and curvature continue across its end
# (360 deg back to 0) within this: the points there are the plan's at TDC, equal up to round-off
CAM_TIGHTEST_MM = 1e-9  # [mm] the tightest slide tolerance a cam's points are placed to (the slide's height
# carries about 1e-13 mm of round-off)
SPEED_RESOLUTION = 1e-4  # relative: a cam's highest master speed is found to this share (0.01 %)
BINDING_SHARE = 1e-4  # relative: a check within this share of its limit binds (the reports' binding list,
# where a limit binds in the stage table)
CROSSED_PCT = 1e-4  # [%] a verified motion this far above the certified upper bound is within the
# verification's tolerance (LIMIT_REL_TOL of the strokes, as a percentage with room)

# --- round-off: the same number computed two ways -----------------------------------------------------------

SAME_RELATIVE = 1e-12  # relative: two values of one quantity this close are equal (a draw speed at its
# bound, a height at the die height, a speed at a limit)
SAME_ANGLE_RAD = 1e-12  # [rad] two crank angles this close are the same angle (a key angle of a plan and of
# its case; a node on a key angle)
SAME_SPEED_RAD_S = 1e-12  # [rad/s] two crank speeds this close are the same (a plan's draw speed at the
# case's bound)
SAME_TIME_S = 1e-12  # [s] a grid point this close to a knot is the knot
KNOT_TIME_S = 1e-9  # [s] a time this close after a knot is the knot (where a key point falls; a left
# limit at a knot is taken this share of the segment before it)
SAME_POSITION_MM = 1e-9  # [mm] a robot this close to a point of its interference curve is at it (its position
# sums its move's pieces: about 1e-13 mm of round-off at the die centre)
SAME_HEIGHT_MM = 1e-9  # [mm] a height this far outside the stroke still counts as its end; the die height
# counts up to this
MIRROR_HEIGHT_MM = 1e-9  # [mm] a mechanism is its own mirror about 180 deg where the slide's heights either side
# agree this closely (planning.model.pendulum.mirror_symmetric)
SAME_SCORE = 1e-9  # [s, or the objective's normalised score] a solution must beat the best by this to
# replace it (two starts that agree to round-off keep the first)
SAME_SPM = 1e-9  # [strokes/min] a neighbour's plan must beat a sweep point by this to replace it
SAME_START_REL = 1e-9  # relative: two starts of the NLP this close are the same start (atol SAME_ANGLE_RAD)
BETTER_SHARE = 1e-9  # relative: a plan from a neighbour replaces the cold one when its period is this share
# shorter (below it the two are the same optimum, and the cold solve's answer stands)
RATE_TOLERANCE = 1e-9  # relative: a target rate this close above the fastest the limits allow is that rate
SAME_PERIOD_S = 1e-9  # [s] a plan whose period is this close to the target cycle time runs at the rate
DEAD_CENTRE_SLOPE = 1e-9  # relative to the largest |h'|: a node where the slide stands (a dead centre)
SAME_NODE_RAD = 1e-9  # [rad] a zero of h' this close to TDC or BDC is that dead centre
ANGLE_ROUND_OFF_RAD = 1e-14  # [rad] the time-at-angle search stops when the angle is met this closely
DEAD_CENTRE_BRACKET_RAD = 1e-13  # [rad] a dead centre's bisection stops at this bracket width
ROOT_STEP_RAD = 1e-14  # [rad] the crossing search stops when its steps are this small
HALF_ULP_REL = 5e-16  # relative: half a unit of the last digit of a number written in exponent form
MIN_LOOP_ROOM = 1e-6  # a linkage's loop whose closing room (a squared sine of its transmission angle) falls
# below this locks: the geometry is refused as no press (a transmission angle under 0.06 deg)
TINY = 1e-300  # a floor against division by zero (never a tolerance of a figure)
TINY_SCALE = 1e-12  # a floor of a scale that may be zero (a limit of 0: binding relative to this)
TINY_RATE = 1e-9  # [s, rpm] a floor of a time or a speed one divides by (a progress rate, a motor speed)

# --- the solver: what IPOPT reaches and how far inside its limits an NLP plans ------------------------------

IPOPT_TOL = 1e-10  # IPOPT's overall tolerance (scaled): far below the verification's, so that a plan at an
# optimum is on its limits to round-off
IPOPT_CONSTR_VIOL_TOL = 1e-10  # IPOPT's constraint violation (rows scaled to 1 at their limits)
IPOPT_RATE_TOL = 1e-6  # the rate NLPs' tolerance: their objective (heat, energy) is flat at the optimum; the
# limits still hold to IPOPT_CONSTR_VIOL_TOL
IPOPT_FREE_RATE_ACCEPTABLE = 1e-3  # the optimal law's rate NLP stops at IPOPT's "acceptable" level: its scaled
# optimality error this low (the free profile's rounded torque kinks leave a dual residual near 1e-4 that IPOPT's
# line search cycles on for hundreds of iterations, the objective fixed to 1e-7) ...
IPOPT_FREE_RATE_OBJ_CHANGE = 1e-6  # ... while the objective (normalised to 1 at the baseline) moves less than
# this from one iteration to the next (the millionth the rate NLPs want) ...
IPOPT_FREE_RATE_COMPL = 1e-4  # ... and the complementarity is this low; the rows still hold to IPOPT_CONSTR_VIOL_TOL
IPOPT_MU_INIT = 1e-6  # a warm start's barrier parameter: the start is near the optimum
IPOPT_FREE_WARM_MU_INIT = 1e-8  # the optimal law's warm start (hundreds of variables near their bounds)
IPOPT_WARM_PUSH = 1e-9  # a warm start's bound pushes (bound, multiplier, slack): stay where the start is
REFINE_MARGIN = 1e-5  # relative: a refined sampled limit is tightened this much beyond the measured overshoot
ROW_ACTIVE = 1e-6  # a row scaled to 1 at its limit is active above 1 - this
AGREE_S = 1e-6  # [s] two starts whose best periods agree this closely have found the same optimum
ACCEL_BACKOFF = 5e-4  # the NLPs hold |slider acceleration| <= (1 - this) x limit at their samples (the
# acceleration peaks between samples by up to this much on the shipped cases)
HARDER_BACKOFF = 5e-3  # the slider acceleration's back-off of a second round when no start verified
DRAW_SPEED_BACKOFF = 1e-4  # the NLP holds a draw's set slide speed this much inside (within its 0.1 % band)
SPEED_BACKOFF = 5e-4  # the NLPs hold |slider speed| <= (1 - this) x limit at their samples
DRIVE_BACKOFF = 5e-5  # the NLPs hold the motor's peak and RMS torque this much inside (refined if exceeded)
GRID_BACKOFF = 5e-5  # the NLPs hold the grid's peak this much inside (refined if exceeded)
MIN_SPEED_BACKOFF = 1e-2  # relative: the optimal law's sampled minimum crank speed is held this much above
# its limit (the speed is cubic between samples and may dip below them)
RMS_PROOF_MARGIN = 1e-3  # relative: the RMS precheck's trapezoidal draw integral is far more accurate
STORAGE_ROOM = 1e-3  # relative: a storage that holds the grid limit with this share of its energy to spare
# is taken as able to (the grid limit's precheck)
PEAK_SLACK = 1e-9  # relative: the second peak-shaving programme keeps the grid peak within this share of the first's
PEAK_FALLBACK_SLACK = 1e-7  # relative: its room when HiGHS finds the first's peak too tight
PEAK_BISECTION_TOL = 1e-12  # relative: the least peak's bisection stops this close to it
JERK_TIE_BREAK = 1e-5  # the optimal law's swings: the mean squared jerk (over its scale's) weighed this much beside
# the cycle time, so that of the many equally fast jerk profiles the smoothest is the one answer
