"""The cohort method's tuning constants, in one frozen object: :class:`CohortOptions`.

What a user sets is not here: the time step ``dt``, the cell ``h``, the tolerance ``tol``
and the cycle budget ``max_iter`` are the arguments of :func:`micro.cohort.cycle_cohorts`
(``method=micro.Cohort(dt=..., h=..., tol=..., max_iter=...)`` in :func:`micro.stationary`),
checked there.  Of the fields below, the few a user may reasonably change (for a study, by
:func:`override`; each changes the results, and the validation record holds only the
defaults) are:

- ``MAX_CELLS``: the memory cap on the cohorts' cells (about 50 MB at the default), for
  a machine with more or less memory;
- ``CELL_FLOOR``: the mass below which a cell is dropped (a part of the map's round-off;
  studies/micro_cohort_near_vc_check.py and micro_cohort_newton_krylov.py vary it);
- ``GRADED_MAX``: how much longer than ``dt`` the steps in the middle of a long loading
  phase may be (1: uniform steps; studies/micro_cohort_graded.py);
- ``SHORT_PHASE``: below which loading phase the steps shrink with it (the resolution
  close to V^c).

The rest are the method's internals, each with the measurement that set it (the comment
above each field; docs/reference/micro_cohort.md and docs/validation/micro_cohort.md).
The field names are those the measurements name (they were module constants of
``micro/cohort.py``).  Not here: the kernels' constants (``micro.cohort.kernels``:
``CHUNKS``, ``PARALLEL_COHORTS``, ``ROUND``), which numba compiles into the cached
kernels, ``WINDOW`` (``micro.cohort.estimate``: the error rules' formulas are written
for five cycles), and ``CUTOFF_TAIL`` (``micro.methods``, with the check of where the method
applies: a command line makes it before it loads the cohort's kernels).

The solver reads :data:`DEFAULT` when it needs a constant, so replacing it (a test's
``monkeypatch.setattr(options, "DEFAULT", dataclasses.replace(options.DEFAULT, ...))``,
or :func:`override`) changes the runs that follow in this process.
"""
from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Iterator
from dataclasses import dataclass

__all__ = ["CohortOptions", "DEFAULT", "override"]


@dataclass(frozen=True)
class CohortOptions:
    """The cohort method's tuning constants (module docstring); every field is a finite
    number > 0 (the ratios below 1; ``AGE`` in [0, 1]; ``PEAK_CREEP`` >= 0, 0 replaying every
    loading phase's end; ``GRADED_MAX`` >= 1, inf for no cap; the counts integers, >= 1 but
    the backtracks, >= 0; ``BAND_ABOVE`` below ``BAND_COLOURS``).

    Raises
    ------
    ValueError
        Naming the field and its range, if a value is out of it.
    """

    # ---------------------------------------------------------------- the coarse transient
    #: The transient's fixed point (at twice the step and cell) is solved to this multiple of
    #: the run's tolerance, and at least to COARSE_FLOOR: its change to the run's own is the
    #: run's discretisation error, so its own error must stay below that change.
    COARSE_TOL: float = 4.0
    #: (the coarse transient's tolerance at least this; see COARSE_TOL)
    COARSE_FLOOR: float = 3e-4
    # ---------------------------------------------------------------- the state
    #: Cells whose surviving mass (a fraction of all blocks) is below this are dropped.
    CELL_FLOOR: float = 1e-13
    #: Most cells the cohorts may hold (about 50 MB).
    MAX_CELLS: int = 3_000_000
    #: A step's Newton iteration for its slip starts at this fraction of the slip rate
    #: extrapolated from the two steps before, times its length (:meth:`_Cohorts.root`).
    WARM: float = 0.97
    #: The newborns of a step made their last jumps this fraction of it before its end, on
    #: average (they cross at a steady rate; the re-jumps are counted to the end).
    AGE: float = 0.5
    # ---------------------------------------------------------------- the cycle map
    #: The start of a shock is located to this fraction of the time step.
    FOLD_TOL: float = 1e-7
    #: A step whose creep exceeds this fraction of the drive keeps a snapshot of the state
    #: before it, from which the end of the loading phase is replayed finely for the peak.
    PEAK_CREEP: float = 0.2
    #: Where the replay found the peak less than this above the stress at the shock's start
    #: (total shocks, small k0: 1e-12 and less), the next cycles of the run skip it.
    PEAK_FLOOR: float = 1e-10
    #: A loading phase shorter than this is resolved with steps ``dt * T / SHORT_PHASE`` (T its
    #: length): 50 steps at the default dt = 0.01, twice as many at half the dt (so that
    #: halving dt refines close to V^c too).
    SHORT_PHASE: float = 0.5
    #: Long loading phases are graded: a step ``dt`` within ``1 / gamma`` (the dashpots'
    #: relaxation time) of the shock before and of the loading phase's end, longer in between
    #: (``dt`` times the distance to the nearer end in units of ``1 / gamma``, at most
    #: GRADED_MAX times ``dt``; :func:`~micro.cohort.cycle._step_length`).  The end is that of
    #: a reference loading phase, kept until a loading phase differs from it by more than
    #: GRADED_SLACK / gamma (a grid that followed every cycle's length would feed back on the
    #: shock's start).
    GRADED_MAX: float = 4.0
    #: (how far a loading phase may differ from the reference one, in 1 / gamma; see GRADED_MAX)
    GRADED_SLACK: float = 0.25
    # ---------------------------------------------------------------- Anderson's acceleration
    #: Anderson's acceleration (close to V^c): the window.
    ANDERSON_WINDOW: int = 10
    #: The evaluations without progress after which Anderson's iteration stops.
    ANDERSON_STALL: int = 8
    #: Anderson's map is on the marginal of the blocks a shock made jump (the others carried
    #: from one evaluation to the next): it is used only where those others are at most this
    #: fraction.
    ANDERSON_UNJUMPED: float = 1e-3
    #: Anderson's iteration stops when its step (the preconditioned residual, about the
    #: distance to the fixed point, in mass) is below this times ``tol``: sigma moved by about
    #: 0.15 of the step there (k0 = 1e-4, 0.95 V^c), so the plain cycles after it find their
    #: steps below tol / 100.
    ANDERSON_TOL: float = 0.05
    #: Halvings of a step whose cycle the map does not apply to (a changed time step, too
    #: many blocks unjumped) before Anderson's iteration gives up.
    ANDERSON_BACKTRACKS: int = 3
    #: The band preconditioner of Anderson's map (:func:`~micro.cohort.solver._band_preconditioner`):
    #: BAND_COLOURS cycles at frozen slips, each from every BAND_COLOURS-th node, and a node's
    #: image taken from BAND_COLOURS - BAND_ABOVE nodes below it to BAND_ABOVE - 1 above (a
    #: block's delta_R moves by a few nodes in a cycle, with an exponential tail downwards).
    BAND_COLOURS: int = 16
    #: (the nodes above a node that its image is taken from, plus one; see BAND_COLOURS)
    BAND_ABOVE: int = 6
    #: The forward-difference step of the full map's response to a shift of the marginal.
    SHIFT_FD: float = 1e-4
    # ---------------------------------------------------------------- Newton-Krylov
    #: Where the frozen map grows (its slowest multiplier >= 1: Anderson's preconditioner bounds
    #: nothing), the fixed point is solved by Newton-Krylov on the whole cycle map
    #: (:func:`~micro.cohort.solver._newton`), each cycle quantity to this fraction of ``tol``
    #: (its change over the last Newton step, which bounds the error of the iterate after it:
    #: at k0 = 1e-3, 0.85 V^c the step that moved sigma_max by 2.8e-5 left it 2.4e-7 from the
    #: fixed point, which a third step, 27 cycles, then showed at the former 0.1).
    NEWTON_TOL: float = 0.5
    #: The forward-difference step of a Jacobian-vector product, in mass (the marginal has mass 1).
    FD_STEP: float = 1e-5
    #: GMRES solves each Newton system to this relative residual (an inexact Newton step).  At
    #: k0 = 1e-3, V = 70 (0.87 V^c) the first step's residual falls to 1.5e-5 of the mass at
    #: 1e-2 and 1e-3 alike (the map's nonlinearity, not GMRES, limits it), in 15 cycles
    #: instead of 19, and the whole solve takes 33 cycles instead of 44 (sigma_max within 2e-8).
    GMRES_RTOL: float = 1e-2
    #: At most this many Jacobian-vector products (cycles) per Newton step.
    GMRES_MAX: int = 60
    #: Halvings of a Newton step whose residual did not fall, before the iteration stops.
    NEWTON_BACKTRACKS: int = 3
    #: Newton steps at most.
    NEWTON_MAX: int = 8
    # ---------------------------------------------------------------- the multipliers
    #: The leading multipliers: Arnoldi's Krylov space (scipy's ``eigs``).  (12 vectors to
    #: 1e-3: 14 cycles at k0 = 0.01 and 0.1, 0.5 V^c, the leading multiplier within 3e-4 of
    #: the one from 25 vectors to 1e-4, which takes four times as many cycles.)
    MULTIPLIER_NCV: int = 12
    #: (Arnoldi's tolerance; see MULTIPLIER_NCV)
    MULTIPLIER_TOL: float = 1e-3
    # ---------------------------------------------------------------- the error estimate
    #: A run whose five-cycle window contracts by more than this a cycle is accelerated (where
    #: the loading phase is shorter than SHORT_PHASE and shocks all but total); one that
    #: extrapolated (Aitken) such a sequence without the acceleration says in its message that
    #: its error estimate can miss a slower mode (measured:
    #: studies/micro_cohort_estimate_check.py).  (Steps below tol / 100 say nothing alone:
    #: they can be a stress passing through zero steps; the state's move bounds what remains,
    #: :func:`~micro.cohort.estimate._state_tail`.)
    SLOW_CAVEAT: float = 0.9
    #: A last step d between cycles leaves at most STILL * d to go when they contract by 0.8 a cycle.
    STILL: float = 5.0
    #: Aitken's extrapolation only where every ratio of successive steps is at most this: five
    #: cycles cannot tell a ratio closer to 1 from a drift, and a ratio a hair below 1 sends
    #: the extrapolation anywhere (a period of -0.43 from cycles at 0.2097, steps of 2.5e-8 a
    #: cycle); such a sequence is judged as one that does not contract.
    AITKEN_MAX_RATIO: float = 0.999
    #: The stresses' response to the state's move (:func:`~micro.cohort.estimate._state_tail`)
    #: is the largest over this many cycles.  It falls as the fast modes die (at k0 = 0.3,
    #: 0.95 V^c from 1e-2 to 1e-3 of stress per unit of mass over 40 cycles: the largest over a
    #: whole run claimed 30 times the distance, and at 0.99 V^c took 146 cycles where 86 do)
    #: and rises as the slowest mode takes over after a kink (at 0.99 V^c from 2e-4 to
    #: 4.8e-4): over 10 or 15 cycles it claimed 0.8 of the distance at two cycles there, over
    #: 5 cycles 0.8 at another path's stop; over 20 it covered every cycle of the sequences
    #: replayed (studies/micro_cohort_state_tail_check.py, docs/validation/micro_cohort.md
    #: section 5).
    SENSITIVITY_WINDOW: int = 20

    def __post_init__(self) -> None:
        below_one = ("SLOW_CAVEAT", "AITKEN_MAX_RATIO", "ANDERSON_UNJUMPED")
        for f in dataclasses.fields(self):
            value, name = getattr(self, f.name), f.name
            if f.type == "int":
                least = 0 if name.endswith("BACKTRACKS") else 1
                ok = isinstance(value, int) and not isinstance(value, bool) and value >= least
                allowed = f"an integer >= {least}"
            elif name == "AGE":
                ok, allowed = _number(value) and 0.0 <= value <= 1.0, "a number in [0, 1]"
            elif name == "PEAK_CREEP":
                ok, allowed = _number(value) and value >= 0.0, "a finite number >= 0"
            elif name == "GRADED_MAX":
                ok, allowed = _number(value, inf=True) and value >= 1.0, "a number >= 1 (inf: no cap)"
            elif name in below_one:
                ok, allowed = _number(value) and 0.0 < value < 1.0, "a number in (0, 1)"
            else:
                ok, allowed = _number(value) and value > 0.0, "a finite number > 0"
            if not ok:
                raise ValueError(f"CohortOptions {name} must be {allowed}, got {value!r}")
        if not self.BAND_ABOVE < self.BAND_COLOURS:
            raise ValueError(f"CohortOptions BAND_ABOVE must be below BAND_COLOURS = {self.BAND_COLOURS}, "
                             f"got {self.BAND_ABOVE!r}")


def _number(value, inf: bool = False) -> bool:
    """Whether ``value`` is a real number (not a bool), finite (or +inf where ``inf``)."""
    return (isinstance(value, (int, float)) and not isinstance(value, bool)
            and (math.isfinite(value) or (inf and value == math.inf)))


#: The options every run reads (replace it, not its fields: it is frozen).
DEFAULT = CohortOptions()


@contextlib.contextmanager
def override(**changes) -> Iterator[CohortOptions]:
    """Within the ``with`` block, :data:`DEFAULT` with ``changes`` (field names, checked by
    :class:`CohortOptions`); restored after it.  For studies in one process (a pool's
    workers forked inside the block inherit it; others do not)."""
    global DEFAULT
    old = DEFAULT
    DEFAULT = dataclasses.replace(old, **changes)
    try:
        yield DEFAULT
    finally:
        DEFAULT = old
