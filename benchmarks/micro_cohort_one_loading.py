"""One loading phase from the same state: the cohort method against the Fokker-Planck grid.

k0 = 0.01, V = 0.9 V^c (Fig. 4 parameters), where the cohorts' cycle and the N-block's
differ by 3e-4 in sigma_max.  The state is the cohorts' state after a shock (160 cycles
from the first shock's image at dt = 0.004, h = kappa zbar / 20; a product state:
Exp(kappa zbar) margins times the delta_R marginal of the last shock's blocks).  From it
one loading phase is run by the cohorts and by the grid's shock-to-shock map
(``micro.cycle``: Fokker-Planck loading, the shock's start replayed in finer steps) at
shrinking bins.  If the grid converges to the cohorts' sigma_max, the cohorts load
correctly and a gap lies elsewhere.

    python benchmarks/micro_cohort_one_loading.py        # about 5 minutes on 1 core
"""
from __future__ import annotations

import math
import time

import micro
from micro import cycle as CY
from micro.cohort import _one_cycle, _start
from micro.grid import GridSettings


def main() -> None:
    model = micro.Model(k0=0.01)
    V = 0.9 * micro.critical_velocity(model).Vc
    h, dt = model.kappa * model.zbar / 20.0, 0.004
    st = _start(model, V, h, None)
    for _ in range(160):
        out = _one_cycle(st, dt)
    print(f"cohorts after 160 cycles: sigma_max {out['sigma_max']:.6f}, period {out['period']:.4f}")
    nodes, masses = st.marginal(st.n - 1)  # the last shock's newborn cohort
    p = (nodes, masses / masses.sum())
    one = _one_cycle(_start(model, V, h, p), dt)
    print(f"cohorts, one loading from the product state: sigma_max {one['sigma_max']:.6f}, "
          f"period {one['period']:.4f}")
    for eps in (0.008, 0.004, 0.002, 0.001):
        settings = GridSettings(eps=eps, theta_shift=0.5, theta_relax=0.5, dt_max=math.inf)
        half = int(math.ceil(45.0 * model.k2 * model.zbar / eps)) + 8
        x, _ = CY._rows(p[0], p[1], eps, -half, 2 * half)
        t = time.perf_counter()
        res = CY._Map(model, settings, V, t_max=20.0 * model.kappa * model.zbar / (model.k0 * V), j_lo=-half)(x)
        print(f"grid, eps = {eps:g}: sigma_max {res['sigma_max']:.6f}, period {res['period']:.4f} "
              f"({time.perf_counter() - t:.1f} s)")


if __name__ == "__main__":
    main()
