"""What the user sets: the comparison's parameters, in one frozen dataclass that
validates itself on construction (a bad value fails at once and names itself).

Three presets: :meth:`Settings.default` (the paper's parameters, sized to finish in
about a minute on 2 cores), :meth:`Settings.quick` (a smoke run, what the tests use) and
:meth:`Settings.paper` (more points, finer N-block runs and the paper's Figs. 3 and 10;
opt-in, minutes).  Any
field can be changed with :func:`dataclasses.replace` or :meth:`Settings.with_`.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np

import micro
import rsf

from ._validation import choice, choices, in_range, positive, positive_array, positive_int

__all__ = ["Settings", "SCENARIOS", "PAPER_K0", "PAPER_SETS"]

#: The scenarios of a report, in the order they run.
SCENARIOS = ("bifurcation", "hopf", "phase", "shs")

#: k0 of the paper's Figs. 4 and 8.
PAPER_K0 = (0.3, 0.1, 0.01, 0.001, 0.0001)

#: (k1, k2) of the paper's Fig. 5, bottom to top.
PAPER_SETS = ((0.0, 1.0), (0.1, 0.9), (0.5, 0.5), (0.9, 0.1))
#: V / V^c of the default stick-slip points of D_c (a), the same five at every k0: enough
#: cycles to fix D_c (a) at each k0 alone (``dc_per_k0``), spread over micro's stick-slip side.
DC_RATIOS = (0.15, 0.25, 0.4, 0.55, 0.7)


def _velocity_ratios(name: str, values) -> tuple[float, ...]:
    return tuple(sorted(positive_array(name, values, low=0.0, high=1e6)))


def _stick_slip_points(name: str, pairs) -> tuple[tuple[float, float], ...]:
    """(k0, V / V^c) pairs, each checked, without duplicates, largest k0 first."""
    points = []
    for i, pair in enumerate(pairs):
        if len(tuple(pair)) != 2:
            raise ValueError(f"{name}[{i}] must be a (k0, V / V^c) pair, got {pair!r}")
        points.append((in_range(f"{name}[{i}].k0", pair[0], 0.0, 10.0, low_open=True),
                       in_range(f"{name}[{i}].ratio", pair[1], 0.0, 1.0, low_open=True, high_open=True)))
    return tuple(sorted(set(points), key=lambda p: (-p[0], p[1])))


def _geom(lo: float, hi: float, n: int) -> tuple[float, ...]:
    return tuple(float(f"{v:.6g}") for v in np.geomspace(lo, hi, n))


@dataclass(frozen=True)
class Settings:
    r"""Parameters of a comparison run.

    Model (the paper's Figs. 3-4): ``k1, k2, zbar`` (exponential pinning distances with
    mean ``zbar`` and cutoff ``cutoff``), ``eta_u = f_th = 1``.

    Micro's steady branch and V^c are exact (the direct method, ``micro.steady_sliding``
    and ``micro.critical_velocity``, to 1e-11).  Its stick-slip points on the bifurcation
    diagram and in the transition study are limit cycles solved by ``cycle_method``:
    ``"cohort"`` (the default, micro's own default for cycles, :mod:`micro.cohort`: no grid
    in the margin, the fixed point of the cycle map to ``cycle_rtol`` times the velocity
    weakening ``f_th - sigma_fast_limit``, about 1e-4 in stress, at the time step
    ``cycle_dt``, each row with its discretisation error where it is known) or ``"fp"`` (the Fokker-Planck equation at the
    bin ``eps``, whose cycles are off by about 1e-3 at eps = 0.016).  The transition study
    also runs the N-block simulation.  Slide-hold-slide and the traces time-step the
    Fokker-Planck equation at ``eps`` with the stopping rule ``rtol``, ``atol``, ``t_max``
    (None: micro's default).

    Parameters
    ----------
    k0 : stiffnesses of the bifurcation diagram (Figs. 4/8): micro's exact V^c and steady
        branch at each; the RS side always shows the paper's five.
    branch_points, branch_span, branch_V_max : stable-branch velocities per k0, log-spaced
        from V^c (1 + 1e-3) to min(branch_span V^c, branch_V_max) (at least 10 V^c).
    unstable_points, unstable_from : velocities of the unstable branch (its growth rate),
        from unstable_from V^c to 0.995 V^c.
    reference_k0, reference_V : a stiffness k0 >= k2, at which micro slides steadily at
        every V; its branch on ``reference_V`` reaches V ~ B and pins the shape of Eq. (10).
    fp_points : (k0, V / V^c) of the stick-slip points that the D_c fit matches (with
        exact steady points at ``steady_ratios`` V^c at the same k0): by default five
        (``DC_RATIOS``) at each of the paper's five k0, so that D_c (a) is fitted at every k0
        and also at each k0 alone from five cycles (``dc_per_k0``); ``fp_k0`` is the set of their k0 (the names are older than the
        cohort method: the points are solved by ``cycle_method``).  With ``cycle_method="fp"``, the FP's cost grows near V^c (a
        cycle a few bins high settles slowly), at k0 = 0.3 faster than at 0.1.
    shown_points : (k0, V / V^c) of stick-slip points drawn on the diagram (by
        ``cycle_method``) but not matched by the fit (none by default).
    cycle_method, cycle_rtol : how the stick-slip points are solved (above).
    cycle_dt : the cohort method's time step for the report's cycles (its cell is micro's
        default, ``kappa zbar / 20``).  0.02, twice micro's default: the extrema move by
        1e-5 to 2e-5 from dt = 0.02 to 0.01 at k0 = 0.3 to 1e-3, 0.4 V^c (as much as
        halving the cell moves them), far below what the D_c fit resolves, for a third of
        the cost (docs/validation/micro_defaults.md, "The report's time step").
    dc_bounds, dc_grid, bootstrap : D_c search range, scan resolution, bootstrap samples.
    hopf_k0 : k0 of the transition study; ``hopf_distances``: d = (V^c - V)/V^c of its
        cycles (by ``cycle_method``); ``nblock_N``, ``nblock_distances``: the
        N-block sizes and distances, each run over ``nblock_cycles`` shocks after
        ``nblock_discard`` (close to V^c its cycles contract slowly from the relaxed
        start: at k0 = 0.1, d = 0.1 the amplitude after 5 shocks is 1.6e-3 below its
        value after 100, docs/validation/micro_transition.md); ``rs_hopf_distances``:
        the RS ones.
    phase_sets : (k1, k2) sets of Fig. 5; ``phase_points`` k0 per set, log-spaced from
        ``phase_k0_min`` to 0.98 k2 (micro has no stick-slip for k0 >= k2);
        ``phase_reference_V``: velocities of each set's reference branch (the RS law of that
        set is fitted to it).
    rs_points : velocities per k0 of the RS bifurcation curves.
    classical_b : b of the classical RS law, Eq. (7) (raised to 1.5 W(V) if smaller, so
        that a = b - W(V) > 0).
    shs_k0, shs_V, hold_times : slide-hold-slide (Fig. 7): stiffness, drive velocity (must
        be steady) and hold times.
    paper_figures : also the paper's Fig. 3 (sigma(t) at k0 = 0.01 from a start, by the
        N-block with ``fig3_N`` blocks) and Fig. 10 (the FP's sigma against eps at
        ``fig10_k0``, ``fig10_eps``, against the exact value).
        ``fig10_t_max``: each Fig. 10 run stops at this simulated time, settled or not (an
        unsettled one is drawn open, with its time mean over the run's later half): where
        the discretised density oscillates it never settles.  At t_max = 60 every point lies
        within 2.2e-5 of runs of 480 time units (2.4e-5 at 120), in half the time
        (docs/validation/micro_defaults.md, "Fig. 10").
    """

    k0: tuple[float, ...] = PAPER_K0
    k1: float = 0.1
    k2: float = 0.9
    zbar: float = 0.1
    cutoff: float = 10.0
    eps: float = 0.016
    rtol: float = 1e-2
    atol: float = 1e-4
    t_max: float | None = None
    branch_points: int = 40
    branch_span: float = 100.0
    branch_V_max: float = 2e4
    unstable_points: int = 16
    unstable_from: float = 0.02
    reference_k0: float = 1.0
    reference_V: tuple[float, ...] = _geom(1e-3, 1e3, 25)
    fp_points: tuple[tuple[float, float], ...] = tuple((k0, r) for k0 in PAPER_K0 for r in DC_RATIOS)
    shown_points: tuple[tuple[float, float], ...] = ()
    cycle_method: str = "cohort"
    cycle_rtol: float = 1e-3
    cycle_dt: float = 0.02
    steady_ratios: tuple[float, ...] = (1.5, 3.0)
    dc_bounds: tuple[float, float] = (0.005, 0.5)
    dc_grid: int = 41
    bootstrap: int = 400
    rs_points: int = 50
    hopf_k0: float = 0.1
    hopf_distances: tuple[float, ...] = (0.05, 0.1, 0.2, 0.3, 0.45)
    nblock_N: tuple[int, ...] = (10000, 30000)
    nblock_distances: tuple[float, ...] = (0.1, 0.2, 0.3)
    nblock_cycles: int = 10
    nblock_discard: int = 60
    rs_hopf_distances: tuple[float, ...] = _geom(1e-3, 0.6, 12)
    phase_sets: tuple[tuple[float, float], ...] = PAPER_SETS
    phase_points: int = 24
    phase_k0_min: float = 1e-4
    phase_reference_V: tuple[float, ...] = _geom(1e-3, 1e3, 19)
    shs_k0: float = 0.1
    shs_V: float = 10.0
    hold_times: tuple[float, ...] = (0.1, 0.3, 1.0, 2.0, 4.0, 8.0, 16.0)
    classical_b: float = 0.01
    paper_figures: bool = False
    fig3_N: int = 100_000
    fig10_k0: tuple[float, ...] = (0.3, 0.1)
    fig10_eps: tuple[float, ...] = (0.025, 0.02, 0.016, 0.0125)
    fig10_t_max: float = 60.0
    scenarios: tuple[str, ...] = SCENARIOS
    preset: str = "default"

    def __post_init__(self) -> None:
        set_ = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        set_("k0", tuple(sorted(positive_array("k0", self.k0, low=0.0, high=10.0), reverse=True)))
        set_("k1", in_range("k1", self.k1, 0.0, 100.0))
        set_("k2", in_range("k2", self.k2, 0.0, 100.0, low_open=True))
        set_("zbar", positive("zbar", self.zbar))
        set_("cutoff", positive("cutoff", self.cutoff))
        if self.cutoff <= self.zbar:
            raise ValueError(f"cutoff must be > zbar = {self.zbar!r}, got {self.cutoff!r}")
        set_("eps", positive("eps", self.eps))
        set_("rtol", in_range("rtol", self.rtol, 0.0, 0.5, low_open=True))
        set_("atol", in_range("atol", self.atol, 0.0, 0.1))
        if self.t_max is not None:
            set_("t_max", positive("t_max", self.t_max))
        set_("branch_points", positive_int("branch_points", self.branch_points, low=5, high=1000))
        set_("branch_span", in_range("branch_span", self.branch_span, 10.0, 1e6))
        set_("branch_V_max", in_range("branch_V_max", self.branch_V_max, 1.0, 1e7))
        set_("unstable_points", positive_int("unstable_points", self.unstable_points, low=3, high=1000))
        set_("unstable_from", in_range("unstable_from", self.unstable_from, 1e-6, 0.9))
        set_("reference_k0", positive("reference_k0", self.reference_k0))
        if self.reference_k0 < self.k2:
            raise ValueError(f"reference_k0 must be >= k2 = {self.k2!r} (steady at every V), got {self.reference_k0!r}")
        set_("reference_V", _velocity_ratios("reference_V", self.reference_V))
        set_("fp_points", _stick_slip_points("fp_points", self.fp_points))
        set_("shown_points", _stick_slip_points("shown_points", self.shown_points))
        set_("cycle_method", choice("cycle_method", self.cycle_method, ("cohort", "fp")))
        set_("cycle_rtol", in_range("cycle_rtol", self.cycle_rtol, 1e-6, 0.1))
        set_("cycle_dt", in_range("cycle_dt", self.cycle_dt, 0.0, 0.1, low_open=True))
        set_("steady_ratios", tuple(sorted(positive_array("steady_ratios", self.steady_ratios, low=1.0, high=1e4,
                                                          min_size=0))))
        lo, hi = (positive(f"dc_bounds[{i}]", v) for i, v in enumerate(self.dc_bounds))
        if not hi > lo:
            raise ValueError(f"dc_bounds must be increasing, got {self.dc_bounds!r}")
        set_("dc_bounds", (lo, hi))
        set_("dc_grid", positive_int("dc_grid", self.dc_grid, low=7))
        set_("bootstrap", positive_int("bootstrap", self.bootstrap, low=0))
        set_("rs_points", positive_int("rs_points", self.rs_points, low=5))
        set_("classical_b", positive("classical_b", self.classical_b))
        set_("hopf_k0", positive("hopf_k0", self.hopf_k0))
        for name in ("hopf_distances", "nblock_distances", "rs_hopf_distances"):
            values = tuple(sorted(positive_array(name, getattr(self, name), low=0.0, high=1.0,
                                                 min_size=3 if name == "rs_hopf_distances" else 0)))
            if any(d >= 1.0 for d in values):
                raise ValueError(f"{name} must lie in (0, 1), got {getattr(self, name)!r}")
            set_(name, values)
        Ns = []
        for i, n in enumerate(self.nblock_N):
            Ns.append(positive_int(f"nblock_N[{i}]", n, low=100, high=10**7))
        set_("nblock_N", tuple(sorted(Ns)))
        set_("nblock_cycles", positive_int("nblock_cycles", self.nblock_cycles, low=2))
        set_("nblock_discard", positive_int("nblock_discard", self.nblock_discard, low=0))
        sets = []
        for i, pair in enumerate(self.phase_sets):
            if len(tuple(pair)) != 2:
                raise ValueError(f"phase_sets[{i}] must be a (k1, k2) pair, got {pair!r}")
            k1, k2 = pair
            sets.append((in_range(f"phase_sets[{i}].k1", k1, 0.0, 100.0),
                         in_range(f"phase_sets[{i}].k2", k2, 0.0, 100.0, low_open=True)))
        set_("phase_sets", tuple(sets))
        set_("phase_points", positive_int("phase_points", self.phase_points, low=3, high=1000))
        set_("phase_k0_min", in_range("phase_k0_min", self.phase_k0_min, 1e-6, 0.05))
        set_("phase_reference_V", _velocity_ratios("phase_reference_V", self.phase_reference_V))
        set_("shs_k0", positive("shs_k0", self.shs_k0))
        set_("shs_V", positive("shs_V", self.shs_V))
        set_("hold_times", tuple(sorted(positive_array("hold_times", self.hold_times, low=0.0, min_size=3))))
        if not isinstance(self.paper_figures, bool):
            raise ValueError(f"paper_figures must be True or False, got {self.paper_figures!r}")
        set_("fig10_k0", tuple(sorted(positive_array("fig10_k0", self.fig10_k0, low=0.0, high=10.0, min_size=0),
                                      reverse=True)))
        set_("fig10_eps", tuple(sorted(positive_array("fig10_eps", self.fig10_eps, low=0.0, high=1.0, min_size=0),
                                       reverse=True)))
        set_("fig10_t_max", positive("fig10_t_max", self.fig10_t_max))
        set_("fig3_N", positive_int("fig3_N", self.fig3_N, low=100, high=10**7))
        set_("scenarios", choices("scenarios", self.scenarios, SCENARIOS))
        # every time-stepped micro model must accept the bins
        for k0 in self.fp_k0 + (self.hopf_k0, self.shs_k0):
            for eps in (self.eps,):
                self.numerics(eps).settings(self.model(k0))

    # -- presets ---------------------------------------------------------------------------
    @classmethod
    def default(cls, **changes: Any) -> Settings:
        """The paper's parameters, sized for about a minute on 2 cores."""
        return replace(cls(), **changes) if changes else cls()

    @classmethod
    def quick(cls, **changes: Any) -> Settings:
        """A smoke run (seconds once compiled): few points, a coarse bin.  Its numbers only
        show that the pipeline works."""
        base = cls(eps=0.02, branch_points=12, unstable_points=6, reference_V=_geom(1e-3, 1e3, 13),
                   fp_points=((0.1, 0.2), (0.1, 0.4), (0.1, 0.6)), shown_points=((0.001, 0.5),), cycle_rtol=1e-2,
                   steady_ratios=(1.5,), dc_grid=13, bootstrap=50,
                   rs_points=12, hopf_k0=0.1, hopf_distances=(0.4, 0.6, 0.8), nblock_N=(3000, 10000),
                   nblock_distances=(0.1, 0.2, 0.4), rs_hopf_distances=(0.01, 0.1, 0.3, 0.6),
                   phase_sets=((0.5, 0.5),), phase_points=8, phase_reference_V=_geom(1e-3, 1e3, 13),
                   shs_k0=0.3, shs_V=3.0, hold_times=(0.3, 1.0, 3.0, 10.0), preset="quick")
        return replace(base, **changes) if changes else base

    @classmethod
    def paper(cls, **changes: Any) -> Settings:
        """More points, the paper's Figs. 3 and 10, finer N-block runs (opt-in: minutes)."""
        base = cls(branch_points=80, unstable_points=32, reference_V=_geom(1e-3, 1e3, 49),
                   fp_points=tuple([(0.3, r) for r in (0.05, 0.15, 0.3, 0.4, 0.55)] +
                                   [(0.1, r) for r in (0.05, 0.15, 0.3, 0.4, 0.55, 0.7, 0.85)] +
                                   [(k0, r) for k0 in (0.01, 0.001, 0.0001) for r in (0.15, 0.4, 0.55, 0.7, 0.85)]),
                   shown_points=(),
                   steady_ratios=(1.2, 1.5, 2.0, 3.0, 5.0),
                   hopf_distances=(0.02, 0.05, 0.1, 0.2, 0.3, 0.45, 0.6), nblock_N=(30000, 100000),
                   nblock_distances=(0.05, 0.1, 0.2, 0.3, 0.5),
                   rs_hopf_distances=_geom(1e-4, 0.6, 20), phase_points=48,
                   phase_reference_V=_geom(1e-3, 1e3, 37),
                   hold_times=(0.03, 0.1, 0.3, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0), paper_figures=True, preset="paper")
        return replace(base, **changes) if changes else base

    @property
    def fp_k0(self) -> tuple[float, ...]:
        """The k0 of ``fp_points``, largest first."""
        return tuple(sorted({k0 for k0, _ in self.fp_points}, reverse=True))

    def with_(self, **changes: Any) -> Settings:
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)

    # -- what the scenarios build from it --------------------------------------------------
    def model(self, k0: float, k1: float | None = None, k2: float | None = None) -> micro.Model:
        """The micro model at ``k0`` (and optionally another (k1, k2))."""
        return micro.Model(k0=k0, k1=self.k1 if k1 is None else k1, k2=self.k2 if k2 is None else k2,
                           jumps=micro.Exponential(zbar=self.zbar, cutoff=self.cutoff))

    def numerics(self, eps: float | None = None) -> micro.Numerics:
        return micro.Numerics(eps=self.eps if eps is None else eps)

    def convergence(self) -> micro.Convergence:
        return micro.Convergence(rtol=self.rtol, atol=self.atol, t_max=self.t_max)

    def rs_paper_vc(self, k0: float) -> float:
        """RS critical velocity with the paper's constants (Eq. 10, D_c = 0.06); NaN where
        steady sliding is stable at every V (k0 D_c > A / (4 B))."""
        return float(rsf.critical_velocity(rsf.HyperbolicLaw(mu_inf=0.0), k0, rsf.PAPER_DC).Vc)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)
