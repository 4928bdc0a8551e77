"""The runs whose speed should not regress, for airspeed velocity (asv).

Each class's ``setup`` makes the first call, which holds numba's compilation (or the load
of its disk cache) and CVODE's set-up, so that the ``time_*`` functions time the run
alone; ``track_first_call`` times that first call in a new interpreter, apart.  Public
API only.  Run from the repository's top (``pip install -e '.[asv]'`` first)::

    asv run -E existing --set-commit-hash $(git rev-parse HEAD)   # all, results saved
    asv run -E existing --quick -b RSFClassical                    # each once, not saved

The accuracy-versus-cost scripts stay beside this folder (benchmarks/README.md); the
validation studies are in studies/ (studies/README.md).
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

import compare
import micro
import rsf

# rsf's classical spring-slider after a velocity step (issue 38: these runs got 1.3-1.75
# times slower between bd9e37a and 742d67f and nothing noticed; benchmarks/rsf_classical_speed.py
# compares two commits on them): the log law, a = 0.005, b = 0.01, Dc = 10, v0 = 1.
_A, _B, _DC, _V0, _MU0 = 0.005, 0.01, 10.0, 1.0, 0.6
_STEP = {"aging": 10.0, "slip": 2.0}   # the velocity after the step at t = 10, from 1


class RSFClassical:
    """``rsf.simulate`` of the classical spring-slider, a velocity step at t = 10, to t = 60,
    from the exact steady state, output at every internal step; CPU time (one thread)."""

    params = (["aging", "slip"], [1.2, 2.0, 3.0], [1e-6, 1e-10])
    param_names = ["state_law", "k0_over_kc", "rtol"]
    timer = time.process_time

    def setup(self, state_law: str, k0_over_kc: float, rtol: float) -> None:
        self.model = rsf.standard_rs(mu0=_MU0, a=_A, b=_B, Dc=_DC, k0=k0_over_kc * (_B - _A) / _DC, v0=_V0,
                                     state_law=state_law)
        self.protocol = rsf.Protocol.velocity_steps([1.0, _STEP[state_law]], [10.0])
        self.options = rsf.SolverOptions(rtol=rtol, atol=rtol * 1e-2)
        self.initial = rsf.InitialState(perturbation=0.0)
        self.run()  # compilation or cache load, apart

    def run(self) -> rsf.Trajectory:
        return rsf.simulate(self.model, protocol=self.protocol, t_end=60.0, options=self.options,
                            initial=self.initial)

    def time_velocity_step(self, state_law: str, k0_over_kc: float, rtol: float) -> None:
        self.run()


class RSFLimitCycle:
    """``rsf.limit_cycle`` of the paper's Eq. (10) (a = 0: stick, slide and slip phases)."""

    params = ([0.3, 0.01], )
    param_names = ["k0"]
    timer = time.process_time

    def setup(self, k0: float) -> None:
        self.model = rsf.SpringSlider(k0=k0)
        self.V = {0.3: 0.05, 0.01: 0.01}[k0]
        rsf.limit_cycle(self.model, self.V)  # compilation or cache load, apart

    def time_limit_cycle(self, k0: float) -> None:
        rsf.limit_cycle(self.model, self.V)


class MicroSteadyBranch:
    """``micro.steady_sliding`` on 100 velocities from 0.1 to 1000 (k0 = 0.1, Fig. 4
    parameters), with and without the growth rates of the unstable mode."""

    params = ([True, False], )
    param_names = ["growth_rate"]

    def setup(self, growth_rate: bool) -> None:
        self.model = micro.Model(k0=0.1)
        self.V = np.logspace(-1, 3, 100)
        micro.steady_sliding(self.model, self.V[:3], growth_rate=growth_rate)  # compilation, apart

    def time_steady_branch(self, growth_rate: bool) -> None:
        micro.steady_sliding(self.model, self.V, growth_rate=growth_rate)


class MicroCriticalVelocity:
    """``micro.critical_velocity`` (the renewal chain's root of b(V) = 1) at the paper's
    five k0."""

    params = ([0.3, 0.1, 0.01, 0.001, 0.0001], )
    param_names = ["k0"]

    def setup(self, k0: float) -> None:
        self.model = micro.Model(k0=k0)
        micro.critical_velocity(self.model)  # compilation, apart

    def time_critical_velocity(self, k0: float) -> None:
        micro.critical_velocity(self.model)


class MicroCohortCycle:
    """One stick-slip cycle solved by the cohort method: ``micro.stationary(Model(k0=0.01),
    4.0, method="cohort")``, the run timed in docs/validation/micro_results.md ('Threads
    on shared cores')."""

    number = 1
    repeat = (1, 3, 60.0)
    rounds = 1
    warmup_time = 0.0
    timeout = 600.0

    def setup(self) -> None:
        self.model = micro.Model(k0=0.01)
        # the kernels compiled (or loaded) on a short, loose run of the same point
        micro.stationary(self.model, 4.0, method=micro.Cohort(tol=1e-3, max_iter=6))

    def time_cohort_cycle(self) -> None:
        micro.stationary(self.model, 4.0, method="cohort")


class CompareQuickReport:
    """The quick report, ``python -m compare --quick`` as a call: ``compare.report`` with
    ``Settings.quick()``, no cache, one process (serial: steadier on shared cores)."""

    number = 1
    repeat = (1, 2, 120.0)
    rounds = 1
    warmup_time = 0.0
    timeout = 900.0

    def setup(self) -> None:
        self.out = tempfile.mkdtemp(prefix="asv_compare_")
        self.run()  # every kernel the report uses compiled (or loaded), apart

    def teardown(self) -> None:
        shutil.rmtree(self.out, ignore_errors=True)

    def run(self) -> None:
        compare.report(compare.Settings.quick(), out=self.out, use_cache=False, workers=1, progress=False)

    def time_quick_report(self) -> None:
        self.run()


_FIRST_CALLS = {
    "rsf.simulate": "import rsf; rsf.simulate(rsf.standard_rs(mu0=0.6, a=0.005, b=0.01, Dc=10.0, k0=0.001, v0=1.0),"
                    " protocol=rsf.Protocol.velocity_steps([1.0, 10.0], [10.0]), t_end=60.0)",
    "micro.steady_sliding": "import micro; micro.steady_sliding(micro.Model(k0=0.1), 2.0)",
}


def track_first_call(call: str) -> float:
    """Seconds of the import and first call in a new interpreter, numba's disk cache as this
    environment has it (warm after any run): the compile or cache-load time, apart."""
    code = f"import time; t = time.perf_counter(); {_FIRST_CALLS[call]}; print(time.perf_counter() - t)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return float(out.stdout.strip().splitlines()[-1])


track_first_call.params = list(_FIRST_CALLS)
track_first_call.param_names = ["call"]
track_first_call.unit = "seconds"
