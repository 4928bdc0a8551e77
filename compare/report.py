r"""The whole comparison: micro and RS side by side, as tables, figures and ``summary.md``.

:func:`report` runs the scenarios of a :class:`~compare.params.Settings` (``bifurcation``,
``hopf``, ``phase``, ``shs``, and the paper's Figs. 3 and 10 with ``paper_figures``) and
returns a :class:`Report` whose tables are pandas DataFrames; with ``out`` it also writes
them as CSV, the figures as PNG and a summary.

Micro answers by its defaults: the stationary questions directly
(:func:`micro.critical_velocity` and :func:`micro.steady_sliding`: the renewal chain of
one block, milliseconds per V); the stick-slip points of the diagram and of the
transition study are limit cycles solved as fixed points of the cycle map
(:mod:`micro.cohort`, seconds per point at every k0, each with its discretisation error
where it is known), checked in the transition study by the N-block simulation at two
sizes; slide-hold-slide and the paper's fast traces time-step the Fokker-Planck equation
(a method that carries a transient), its slow trace the N-block, and the paper's Fig. 10 is
the FP against its bin.

The code is in three layers:

* :mod:`compare.context`: the settings, the runner, and the stages several scenarios
  share (micro's exact V^c and steady branch, the Eq. (10) fit, D_c two ways), each
  computed when first needed;
* :mod:`compare.scenarios`: one module per scenario, which declares its micro tasks and
  returns its tables, figures and paragraph of the summary;
* this module: :data:`REGISTRY` of the scenarios, and :func:`report`, which runs every
  micro task of the selected scenarios in two batches on the runner (first the exact V^c
  that the other tasks are placed at, then everything else at once, the slowest first,
  so that the pool stays busy), then each scenario, and assembles the report (the
  per-k0 D_c fits and the figures on the pool's workers, idle by then:
  :meth:`~compare.runner.Runner.submit`, :class:`~compare.figures.Painter`).

Every micro evaluation goes through a :class:`~compare.runner.Runner` (disk cache,
process pool or dask); the RS side is fast and recomputed each time.
"""
from __future__ import annotations

import contextlib
import logging
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import pandas as pd

from . import figures, rs_side
from ._validation import positive
from .cache import NullCache, PointCache, check_cache_dir, default_cache_dir
from .context import SHARED_FIGURES, Context, micro_frame
from .output import ReportFolder, check_folder
from .params import Settings
from .runner import Runner
from .scenarios import bifurcation, paper, phase, shs, transition
from .summary import summary
from .tasks import Task, VcTask

__all__ = ["Report", "report", "micro_frame", "REGISTRY"]

log = logging.getLogger(__name__)

#: The scenarios, in the order of the report's figures and summary.  A scenario is a
#: module of :mod:`compare.scenarios` (its interface is described there) and a line here.
REGISTRY = (
    bifurcation,
    transition,
    phase,
    shs,
    paper,
)

#: The order of the second batch by kind of task: the slowest first, since a long point
#: started last would leave the other workers idle.
_SLOWEST_FIRST = {"stationary": 0, "slide_hold_slide": 0, "trace": 1, "nblock": 2, "steady": 3, "vc": 4}


@dataclass
class Report:
    """What :func:`report` computed: tables (DataFrames, also written as CSV), figure paths,
    the summary text, the run time and the runner's statistics.

    ``report[name]`` is the table ``name`` (a KeyError naming the tables if there is none).

    Attributes
    ----------
    settings : Settings
        The settings it ran with (its ``scenarios`` as selected).
    tables : dict of str to pandas.DataFrame
        Every table by name (micro's points, the fits, the RS curves, the settings).
    figures : dict of str to pathlib.Path
        The PNG figures written (empty without ``out``).
    values : dict
        The scalars the summary quotes (fitted constants, D_c, exponents, ...).
    summary : str
        The text of ``summary.md``.
    out : pathlib.Path or None
        The report folder, if one was written.
    wall_time : float
        Seconds the whole report took.
    stats : RunStats
        The runner's counts: points asked for, cached, computed, failed.
    """

    settings: Settings
    tables: dict[str, pd.DataFrame] = field(default_factory=dict)
    figures: dict[str, Path] = field(default_factory=dict)
    values: dict[str, Any] = field(default_factory=dict)
    summary: str = ""
    out: Path | None = None
    wall_time: float = 0.0
    stats: Any = None

    def __getitem__(self, name: str) -> pd.DataFrame:
        if name not in self.tables:
            raise KeyError(f"no table {name!r}; tables: {sorted(self.tables)}")
        return self.tables[name]


def _prefetch(ctx: Context, scenarios: Sequence) -> None:
    """Run every micro task of the shared stages and of ``scenarios`` in two batches: the
    exact V^c that the other tasks are placed at, then all the others at once."""
    k0 = ctx.vc_k0() + [k for sc in scenarios for k in sc.vc_k0(ctx)]
    ctx.run([VcTask(ctx.model(k)) for k in sorted(set(k0), reverse=True)], "micro Vc (direct)")
    tasks: list[Task] = ctx.tasks()
    for sc in scenarios:
        tasks += sc.tasks(ctx)
    ctx.run(sorted(tasks, key=lambda t: _SLOWEST_FIRST.get(t.kind, 0)), "micro")


@contextlib.contextmanager
def _rsf_compiled_beside(runner: Runner):
    """While the pool's workers compile and run micro's tasks, this process compiles rsf's
    kernels in a thread (:func:`compare.rs_side.warm_up`; this process only waits for the
    workers then).  A failure there is logged, not raised: the real call raises it."""
    if not runner.mode.startswith("process pool"):
        yield
        return

    def warm() -> None:
        try:
            log.info("rsf kernels ready after %.1f s", rs_side.warm_up())
        except Exception as exc:  # noqa: BLE001 - the scenario's own call reports it
            log.warning("compiling rsf's kernels ahead failed: %s", exc)

    thread = threading.Thread(target=warm, name="rsf-warm-up", daemon=True)
    thread.start()
    yield  # (on Ctrl-C the daemon thread is not waited for)
    thread.join()


def report(settings: Settings | None = None, *, out: str | Path | None = None,
           scenarios: Sequence[str] | None = None, Dc: float | None = None, cache_dir: str | Path | None = None,
           use_cache: bool = True, workers: int | None = None, scheduler: Any = None,
           progress: bool = True) -> Report:
    """Run the comparison and (with ``out``) write the report folder.

    Parameters
    ----------
    settings : Settings, optional
        Default :meth:`Settings.default`.
    out : path, optional
        Folder for PNG figures, CSV tables and ``summary.md`` (created).
    scenarios : sequence of str, optional
        Subset of ``('bifurcation', 'hopf', 'phase', 'shs')``; default ``settings.scenarios``.
        (The paper's Figs. 3 and 10 come with ``bifurcation`` when ``settings.paper_figures``.)
    Dc : float, optional
        Use this D_c instead of fitting it to the stick-slip extrema (D_c from V^c
        matching is still reported); within ``settings.dc_bounds``, the fit's range.
    cache_dir, use_cache : where micro records are cached (default: ``$COMPARE_CACHE_DIR`` or
        ``~/.cache/frictionkit-compare``), or no cache at all.
    workers : int, optional
        Local worker processes (default: the cores this process may use; 1 runs in this
        process); see :class:`~compare.runner.Runner`.
    scheduler : str or distributed.Client, optional
        A dask.distributed scheduler to run the micro tasks on instead.
    progress : bool
        Show progress bars (default True).

    Returns
    -------
    Report
        The tables, the figures' paths (with ``out``), the scalars and the summary text.

    Raises
    ------
    ValueError
        If ``settings`` is not a :class:`~compare.params.Settings`, ``scenarios`` names an
        unknown scenario, ``Dc`` is not a finite number in ``settings.dc_bounds``, ``out`` cannot be written (a
        file, a non-empty folder no report wrote, no write permission: checked before any
        computation), ``cache_dir`` is a file, cannot be written, or is ``out`` or inside it
        (checked before any computation too), ``workers`` is not an integer >= 1 or
        ``scheduler`` is neither an address nor a client (or dask is missing).

    Examples
    --------
    >>> import compare
    >>> rep = compare.report(compare.Settings.quick(), out="report")   # doctest: +SKIP
    >>> print(rep.summary)                                               # doctest: +SKIP
    """
    start = time.perf_counter()
    settings = Settings.default() if settings is None else settings
    if not isinstance(settings, Settings):
        raise ValueError(f"settings must be a compare.Settings, got {type(settings).__name__}")
    if scenarios is not None:
        settings = settings.with_(scenarios=tuple(scenarios))
    if Dc is not None:
        lo, hi = settings.dc_bounds
        if not lo <= positive("Dc", Dc) <= hi:   # outside, the RS side may have no stick-slip at all
            raise ValueError(f"Dc must be in [{lo:g}, {hi:g}] (the range the D_c fit searches, "
                             f"Settings.dc_bounds), got {float(Dc):g}")
    if out is not None:
        check_folder(out)  # before any computation
    if use_cache:
        check_cache_dir(default_cache_dir() if cache_dir is None else cache_dir, out)
    cache = PointCache(cache_dir) if use_cache else NullCache()
    rep = Report(settings=settings)
    selected = [sc for sc in REGISTRY if sc.wanted(settings)]
    folder = painter = None
    try:
        with Runner(cache, workers=workers, scheduler=scheduler, progress=progress) as runner:
            ctx = Context(settings, runner, Dc)
            with _rsf_compiled_beside(runner):
                _prefetch(ctx, selected)
            parts = []
            for sc in selected:
                log.info("scenario %s", sc.NAME)
                parts.append((sc, sc.run(ctx)))
            rep.stats = runner.stats
            rep.tables, rep.values = dict(ctx.tables), dict(ctx.values)
            for _, part in parts:
                rep.tables.update(part.tables)
                rep.values.update(part.values)
            rep.tables["settings"] = pd.DataFrame([{k: repr(v) if isinstance(v, tuple) else v
                                                    for k, v in settings.to_dict().items()}])
            # the shared stages' figures and D_c paragraph come first, unless a scenario shows them
            presented = {name for sc, _ in parts for name in getattr(sc, "PRESENTS", ())}
            if out is not None:
                folder = ReportFolder(Path(out))
                rep.out = folder.path
                # the figures are drawn on the pool's workers (warm, idle by now) while this
                # process writes the tables
                painter = figures.Painter(folder, runner.submit)
                drawn: dict[str, Path] = {}
                for sc, part in parts:
                    drawn.update(sc.draw(ctx, part, painter))
                shared = {name: ctx.figure(name, painter) for name in SHARED_FIGURES if name not in presented}
                rep.figures = {**{k: p for k, p in shared.items() if p is not None}, **drawn}
                for name, table in rep.tables.items():
                    folder.write(f"{name}.csv", lambda p, t=table: t.to_csv(p, index=False))
                painter.finish()
    finally:
        if painter is not None:  # (once the pool is shut down: no worker writes a figure any more)
            painter.discard()
    rep.wall_time = time.perf_counter() - start
    paragraphs = [ctx.summary(dc="Dc" not in presented)] + [sc.summary(ctx, part) for sc, part in parts]
    rep.summary = summary(ctx, rep, paragraphs)
    if folder is not None:
        folder.write("summary.md", lambda p: p.write_text(rep.summary, encoding="utf-8"))
        folder.finish()
    return rep
