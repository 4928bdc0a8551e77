"""The report's layout: a registry of scenario modules on a shared context, each model built
once; a new scenario is one module and one registry line."""
from __future__ import annotations

import importlib
from collections import Counter
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

import compare
from compare.scenarios import Part

report_module = importlib.import_module("compare.report")

INTERFACE = ("NAME", "wanted", "vc_k0", "tasks", "run", "draw", "summary")


def test_every_scenario_of_the_settings_is_a_registered_module():
    names = [sc.NAME for sc in report_module.REGISTRY]
    assert len(set(names)) == len(names)
    assert set(compare.SCENARIOS) <= set(names)
    for sc in report_module.REGISTRY:
        assert all(hasattr(sc, attr) for attr in INTERFACE), sc.__name__


def test_a_registered_scenario_joins_the_report_and_models_are_built_once(quick_report, tmp_path, monkeypatch):
    _, cache = quick_report
    toy = SimpleNamespace(
        NAME="toy", wanted=lambda s: True, vc_k0=lambda ctx: [ctx.s.shs_k0], tasks=lambda ctx: [],
        run=lambda ctx: Part(tables={"toy": pd.DataFrame({"k0": [ctx.s.shs_k0], "Vc": [ctx.Vc(ctx.s.shs_k0)]})},
                             values={"toy": 1}),
        draw=lambda ctx, part, out: {}, summary=lambda ctx, part: ["## Toy", "", "a paragraph", ""])
    monkeypatch.setattr(report_module, "REGISTRY", report_module.REGISTRY + (toy,))
    settings = compare.Settings.quick(scenarios=("shs",))   # (its validation builds models of its own)
    built = Counter()
    model = compare.Settings.model

    def counting(self, k0, k1=None, k2=None):
        built[(float(k0), self.k1 if k1 is None else k1, self.k2 if k2 is None else k2)] += 1
        return model(self, k0, k1, k2)
    monkeypatch.setattr(compare.Settings, "model", counting)

    rep = compare.report(settings, Dc=0.06, out=tmp_path / "r", cache_dir=cache, workers=1, progress=False)
    assert rep.stats.computed == 0   # every task of the shs scenario is in the quick report's cache
    assert rep["toy"].Vc.iloc[0] > 0 and rep.values["toy"] == 1
    assert (tmp_path / "r" / "toy.csv").exists()
    assert rep.summary.index("## Slide-hold-slide") < rep.summary.index("## Toy\n\na paragraph")
    assert built and max(built.values()) == 1, built.most_common(3)


def test_the_paper_figure_10_runs_stop_at_their_time_budget():
    """Fig. 10's FP runs carry ``fig10_t_max`` as their stopping time (and so in their
    cache key); every other micro task keeps the report's stopping rule."""
    paper = importlib.import_module("compare.scenarios.paper")
    settings = compare.Settings.paper(fig10_t_max=50.0)
    ctx = SimpleNamespace(s=settings, Vc=lambda k0: 1.0, model=settings.model,
                          stationary_task=lambda k0, V, eps, method: compare.tasks.StationaryTask(
                              settings.model(k0), V, settings.numerics(eps), settings.convergence(), method))
    tasks = paper._fig10_tasks(ctx)
    assert len(tasks) == 8
    assert {t.convergence.t_max for t in tasks} == {50.0}
    assert {t.method for t in tasks} == {"fp"} and settings.convergence().t_max is None
    assert compare.Settings.paper().fig10_t_max == 60.0
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="^fig10_t_max must be"):
            compare.Settings.paper(fig10_t_max=bad)


def test_the_paper_figure_3_traces_are_by_the_method_that_carries_each_transient_cheaply():
    """Fig. 3's slow trace (V = 0.001: N-block, cost with the jumps) and its fast ones (FP,
    cost with the simulated time); ``fig3_N`` reaches the N-block task and is validated."""
    paper = importlib.import_module("compare.scenarios.paper")
    settings = compare.Settings.paper(fig3_N=20000)
    ctx = SimpleNamespace(s=settings, model=settings.model)
    tasks = paper._fig3_tasks(ctx)
    assert [(t.segments[0][1], t.method) for t in tasks] == [(0.001, "nblock"), (5.0, "fp"), (9.8, "fp")]
    assert tasks[0].n_blocks == 20000 and tasks[0].describe()["n_blocks"] == 20000
    assert "numerics" not in tasks[0].describe() and "n_blocks" not in tasks[1].describe()
    for bad in (0, 50, 2.5, True):
        with pytest.raises(ValueError, match="^fig3_N must be"):
            compare.Settings.paper(fig3_N=bad)


def test_an_nblock_trace_keeps_each_shocks_peak_and_drop():
    """An N-block trace through total shocks (k0 = 0.01, V = 0.01, N = 5000, two loading
    phases): the stress falls at each shock from its peak to within finite-N noise of the
    exact stress after a total shock, f_th - kappa zbar (micro.sigma_fast_limit, by hand
    from the model), and time runs forward."""
    model = compare.Settings().model(0.01)
    task = compare.TraceTask(model, ((1500.0, 0.01),), compare.Settings().numerics(), n_samples=300,
                             method="nblock", n_blocks=5000)
    r = task.run()
    t, sigma = np.array(r["t"]), np.array(r["sigma"])
    assert r["method"] == "nblock" and np.all(np.diff(t) >= 0.0)
    drops = np.flatnonzero(np.diff(sigma) < -0.03)
    assert len(drops) >= 2
    after = model.f_th - model.kappa * model.zbar
    assert np.all(np.abs(sigma[drops + 1] - after) < 3e-3)
    assert np.all(sigma[drops] > after + 0.05) and sigma.max() == sigma[drops].max()
    with pytest.raises(ValueError, match="^method must be"):
        compare.TraceTask(model, ((1.0, 1.0),), compare.Settings().numerics(), method="cohort")
