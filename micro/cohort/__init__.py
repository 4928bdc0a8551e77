r"""Stick-slip cycles by cohorts of exponential margins: no grid in the margin.

A grid-free solver of the mean-field dynamics (docs/reference/micro_cohort.md).  Between
its own jumps a block's margin is linear in its state at its last jump, with
coefficients common to all blocks born at the same time:

.. math:: \delta(t) = \beta(\tau)\,\delta' + B(t; t_0) - \alpha (1 - e^{-\gamma\tau})\,\delta_R',
          \qquad \beta(\tau) = 1 - \frac{k_2}{\kappa}(1 - e^{-\gamma\tau}),

with :math:`\delta'` and :math:`\delta_R'` its margin and delta_R at birth, :math:`\tau`
its age and :math:`\alpha = (k_0 + k_1)/\kappa`.  With exponential jumps every block
that jumps leaves with :math:`\delta' \sim \mathrm{Exp}(\kappa\bar z)`, independent of the
rest.  So the blocks born in one step (a *cohort*) are Exp(kappa zbar) in
:math:`\delta'` times a density in :math:`\delta_R'`, and the members that have not
jumped again are those above a floor :math:`\delta' > m(\delta_R')`.  Nothing is
discretised in the margin: a cohort's density is piecewise linear on cells of width
``h`` in delta_R, each cell with a floor that is linear or has one kink, and every
crossed mass is an exact integral of an exponential.  A step of length ``dt`` (up to
four times longer in the middle of a loading phase many relaxation times long:
:func:`_step_length`) solves the mean-field closure for its slip (``dX = zbar x`` the
jumps it causes, a crossed block jumping again as a Poisson process of its overshoot);
the loading phase ends where the closure's smallest root
jumps (a fold), located by bisecting the step; the shock is the same closure in zero
time.  Where a near-critical avalanche runs away is then a continuous function of the
state, so the cycle-to-cycle sequence converges smoothly (geometrically) and is
extrapolated by Aitken's method.  ``sigma_max`` is the largest stress of the cycle: the creep before a
shock can outrun the drive, so the stress peaks before the shock starts
(``sigma_before``, the paper's sigma_B; 1e-3 lower at k0 = 0.3).

Shocks need not be total: the blocks a shock leaves unjumped stay in their cohorts
with raised floors (at k0 = 0.1 and 0.3 their cohorts live for many cycles, and the
cost per cycle grows with them; cells whose blocks have all but crossed are dropped).
The kernels sum the cohorts in parallel (numba threads) when there are many.
A step's newborns made their jumps, on average, half a step before its end: their own
relaxation (the terms in their margin at birth) starts there, which makes the method
second order in ``dt`` (``AGE``; first order when it started at the step's end).
Refinement variables: the time step ``dt`` and the cell width ``h`` (measured orders in
benchmarks/micro_cohort_refinement.py).  Needs exponential jumps, and a loading phase
that ends in a shock within ``20 kappa zbar / (k0 V)`` (otherwise ``applicable=False``).

The package, one module per idea: :mod:`micro.cohort.state` (the cohorts, and the
delta_R marginal a run starts from), :mod:`micro.cohort.kernels` (the numba kernels that
sum the cohorts: a step's coefficients, its closure and slip, its commit),
:mod:`micro.cohort.cycle` (the cycle map: a loading phase and its shock),
:mod:`micro.cohort.solver` (the fixed point: plain cycles, Anderson's acceleration,
Newton-Krylov with :mod:`micro.cohort.newton`, the multipliers),
:mod:`micro.cohort.estimate` (the error estimate) and :mod:`micro.cohort.options` (the
tuning constants, one frozen :class:`~micro.cohort.options.CohortOptions`).
"""
from __future__ import annotations

from .solver import cycle_cohorts, cycle_multipliers, not_applicable

__all__ = ["cycle_cohorts", "cycle_multipliers", "not_applicable"]
