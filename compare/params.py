"""What the user sets: the comparison's parameters, in one frozen dataclass that
validates itself on construction (a bad value fails at once and names itself).

Three presets: :meth:`Settings.default` (the paper's parameters, sized to finish in a
few minutes on 2 cores), :meth:`Settings.quick` (a smoke run, what the tests use) and
:meth:`Settings.paper` (every k0 of Figs. 4 and 8, a finer bin; opt-in, hours).  Any
field can be changed with :func:`dataclasses.replace` or :meth:`Settings.with_`.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import micro
import rsf

from ._validation import choices, in_range, positive, positive_array, positive_int

__all__ = ["Settings", "SCENARIOS", "PAPER_K0", "PAPER_SETS"]

#: The scenarios of a report, in the order they run.
SCENARIOS = ("bifurcation", "hopf", "phase", "shs")

#: k0 of the paper's Figs. 4 and 8.
PAPER_K0 = (0.3, 0.1, 0.01, 0.001, 0.0001)

#: (k1, k2) of the paper's Fig. 5, bottom to top.
PAPER_SETS = ((0.0, 1.0), (0.1, 0.9), (0.5, 0.5), (0.9, 0.1))


def _velocity_ratios(name: str, values) -> tuple[float, ...]:
    return tuple(sorted(positive_array(name, values, low=0.0, high=1e6)))


@dataclass(frozen=True)
class Settings:
    r"""Parameters of a comparison run.

    Model (the paper's Figs. 3-4): ``k1, k2, zbar`` (exponential pinning distances with
    mean ``zbar`` and cutoff ``cutoff``), ``eta_u = f_th = 1``.

    Micro numerics: the bin ``eps`` (its error in σ is about second order in eps; the
    default is coarse, see docs/compare.md), and the stopping rule ``rtol`` (the paper's
    1 %), ``atol`` (absolute stress tolerance of the steady test: below the
    discretisation error, it stops runs whose 1 % of a tiny velocity weakening would be
    smaller than the jitter of the grid) and ``t_max`` (None: micro's default).

    Parameters
    ----------
    k0 : driving stiffnesses of the bifurcation diagram (Figs. 4/8).
    diagram_ratios : velocities of the micro diagram as multiples of the RS critical
        velocity with the paper's constants (Eq. 10, D_c = 0.06) — a placement guess only.
    reference_k0 : a stiffness k0 >= k2, at which micro slides steadily at every V; its
        steady branch reaches V ~ B and pins the shape of Eq. (10).
    reference_V : velocities of that branch.
    dc_bounds, dc_grid, bootstrap : D_c search range, scan resolution, bootstrap samples.
    hopf_k0 : k0 of the Hopf-scaling comparison; ``hopf_distances``: (Vc - V)/Vc of the
        micro points; ``hopf_rel_tol``: bisection tolerance of micro's Vc there.
    phase_sets : (k1, k2) sets of Fig. 5; ``phase_k0``: candidate k0 (only k0 < k2 are
        bisected); ``phase_rel_tol``: bisection tolerance; ``phase_eps``: its bin;
        ``phase_reference_V``: velocities of each set's reference steady branch (the RS law
        of that set is fitted to it).
    critical_k0, critical_rel_tol : k0 whose micro Vc is bisected (at ``eps``) for the
        table of critical velocities, and the bisection tolerance; the other k0 get the
        bracket of their diagram points.
    vc_refine : every micro bisection (critical, Hopf, phase) checks oscillations smaller
        than 2 eps at eps / 2 (``micro.critical_velocity``'s ``refine``): several times
        the cost near Vc, without it Vc carries the grid's error (docs/compare.md).
    rs_points : velocities per k0 of the RS bifurcation curves.
    classical_b : b of the classical RS law, Eq. (7) (raised to 1.5 W(V) if smaller, so
        that a = b - W(V) > 0).
    shs_k0, shs_V, hold_times : slide-hold-slide (Fig. 7): stiffness, drive velocity (must
        be steady) and hold times.
    """

    k0: tuple[float, ...] = (0.3, 0.1, 0.01)
    k1: float = 0.1
    k2: float = 0.9
    zbar: float = 0.1
    cutoff: float = 10.0
    eps: float = 0.016
    rtol: float = 1e-2
    atol: float = 1e-4
    t_max: float | None = None
    diagram_ratios: tuple[float, ...] = (0.15, 0.4, 2.5, 5.0)
    reference_k0: float = 1.0
    reference_V: tuple[float, ...] = (0.1, 0.3, 1.0, 3.0)
    dc_bounds: tuple[float, float] = (0.005, 0.5)
    dc_grid: int = 41
    bootstrap: int = 400
    critical_k0: tuple[float, ...] = (0.1,)
    critical_rel_tol: float = 0.1
    vc_refine: bool = True
    rs_points: int = 50
    hopf_k0: float = 0.1
    hopf_distances: tuple[float, ...] = (0.15, 0.3, 0.5, 0.7)
    hopf_rel_tol: float = 0.1
    phase_sets: tuple[tuple[float, float], ...] = PAPER_SETS
    phase_k0: tuple[float, ...] = (0.3,)
    phase_rel_tol: float = 0.25
    phase_eps: float = 0.025
    phase_reference_V: tuple[float, ...] = (0.1, 0.3, 1.0, 3.0)
    shs_k0: float = 0.1
    shs_V: float = 10.0
    hold_times: tuple[float, ...] = (0.1, 0.3, 1.0, 2.0, 4.0, 8.0, 16.0)
    classical_b: float = 0.01
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
        set_("phase_eps", positive("phase_eps", self.phase_eps))
        set_("rtol", in_range("rtol", self.rtol, 0.0, 0.5, low_open=True))
        set_("atol", in_range("atol", self.atol, 0.0, 0.1))
        if self.t_max is not None:
            set_("t_max", positive("t_max", self.t_max))
        set_("diagram_ratios", _velocity_ratios("diagram_ratios", self.diagram_ratios))
        set_("reference_k0", positive("reference_k0", self.reference_k0))
        set_("reference_V", _velocity_ratios("reference_V", self.reference_V))
        lo, hi = (positive(f"dc_bounds[{i}]", v) for i, v in enumerate(self.dc_bounds))
        if not hi > lo:
            raise ValueError(f"dc_bounds must be increasing, got {self.dc_bounds!r}")
        set_("dc_bounds", (lo, hi))
        set_("dc_grid", positive_int("dc_grid", self.dc_grid, low=7))
        set_("bootstrap", positive_int("bootstrap", self.bootstrap, low=0))
        set_("critical_k0", tuple(sorted(positive_array("critical_k0", self.critical_k0, low=0.0, high=10.0, min_size=0),
                                         reverse=True)))
        set_("critical_rel_tol", in_range("critical_rel_tol", self.critical_rel_tol, 0.0, 1.0, low_open=True,
                                          high_open=True))
        if not isinstance(self.vc_refine, bool):
            raise ValueError(f"vc_refine must be True or False, got {self.vc_refine!r}")
        set_("rs_points", positive_int("rs_points", self.rs_points, low=5))
        set_("classical_b", positive("classical_b", self.classical_b))
        set_("hopf_k0", positive("hopf_k0", self.hopf_k0))
        set_("hopf_distances", tuple(sorted(positive_array("hopf_distances", self.hopf_distances,
                                                           low=0.0, high=1.0, min_size=3))))
        set_("hopf_rel_tol", in_range("hopf_rel_tol", self.hopf_rel_tol, 0.0, 1.0, low_open=True, high_open=True))
        sets = []
        for i, pair in enumerate(self.phase_sets):
            if len(tuple(pair)) != 2:
                raise ValueError(f"phase_sets[{i}] must be a (k1, k2) pair, got {pair!r}")
            k1, k2 = pair
            sets.append((in_range(f"phase_sets[{i}].k1", k1, 0.0, 100.0),
                         in_range(f"phase_sets[{i}].k2", k2, 0.0, 100.0, low_open=True)))
        set_("phase_sets", tuple(sets))
        set_("phase_k0", tuple(sorted(positive_array("phase_k0", self.phase_k0, low=0.0, high=10.0), reverse=True)))
        set_("phase_rel_tol", in_range("phase_rel_tol", self.phase_rel_tol, 0.0, 1.0, low_open=True, high_open=True))
        set_("phase_reference_V", _velocity_ratios("phase_reference_V", self.phase_reference_V))
        set_("shs_k0", positive("shs_k0", self.shs_k0))
        set_("shs_V", positive("shs_V", self.shs_V))
        set_("hold_times", tuple(sorted(positive_array("hold_times", self.hold_times, low=0.0, min_size=3))))
        set_("scenarios", choices("scenarios", self.scenarios, SCENARIOS))
        # every micro model must accept the bins (eps <= kappa zbar / 4 for the stiffest-free case)
        for k0 in self.k0 + (self.reference_k0, self.hopf_k0, self.shs_k0):
            self.numerics().settings(self.model(k0))

    # -- presets ---------------------------------------------------------------------------
    @classmethod
    def default(cls, **changes: Any) -> Settings:
        """The paper's parameters, sized for a few minutes on 2 cores."""
        return replace(cls(), **changes) if changes else cls()

    @classmethod
    def quick(cls, **changes: Any) -> Settings:
        """A smoke run (tens of seconds): few points, a coarse bin.  Its numbers only show
        that the pipeline works."""
        base = cls(k0=(0.3,), eps=0.025, diagram_ratios=(0.3, 0.6, 3.0, 6.0), reference_V=(0.1, 0.3, 1.0, 3.0),
                   dc_grid=13, bootstrap=50, critical_k0=(0.3,), critical_rel_tol=0.3, rs_points=12,
                   hopf_k0=0.3, hopf_distances=(0.2, 0.4, 0.6, 0.8), hopf_rel_tol=0.3,
                   phase_sets=((0.5, 0.5),), phase_k0=(0.3,), phase_rel_tol=0.3, phase_eps=0.025,
                   phase_reference_V=(0.1, 0.3, 1.0, 3.0), shs_k0=0.3, shs_V=3.0, hold_times=(0.3, 1.0, 3.0, 10.0),
                   vc_refine=False, preset="quick")
        return replace(base, **changes) if changes else base

    @classmethod
    def paper(cls, **changes: Any) -> Settings:
        """Every k0 of Figs. 4/8 and a denser phase diagram (opt-in: hours on 2 cores)."""
        base = cls(k0=PAPER_K0, diagram_ratios=(0.01, 0.05, 0.1, 0.2, 0.35, 0.5, 0.65, 0.8, 0.9, 1.1, 1.3, 1.6, 2.0, 3.0, 5.0),
                   reference_V=(0.003, 0.01, 0.03, 0.06, 0.1, 0.2, 0.3, 0.6, 1.0, 3.0, 10.0),
                   phase_k0=(0.6, 0.3, 0.1, 0.03, 0.01, 0.003), phase_rel_tol=0.03, phase_eps=0.008,
                   phase_reference_V=(0.01, 0.03, 0.1, 0.3, 1.0, 3.0),
                   hopf_distances=(0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5), hopf_rel_tol=0.005,
                   shs_V=1000.0, hold_times=(0.03, 0.1, 0.3, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0), preset="paper")
        return replace(base, **changes) if changes else base

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

    def rs_guess_vc(self, k0: float) -> float:
        """RS critical velocity with the paper's constants (used only to place points)."""
        cv = rsf.critical_velocity(rsf.HyperbolicLaw(mu_inf=0.0), k0, rsf.PAPER_DC)
        if math.isfinite(cv.Vc):
            return float(cv.Vc)
        return rsf.PAPER_B  # stiff springs: no RS instability; centre the grid on V ~ B

    def diagram_velocities(self, k0: float) -> tuple[float, ...]:
        vc = self.rs_guess_vc(k0)
        return tuple(float(f"{r * vc:.3g}") for r in self.diagram_ratios)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)
