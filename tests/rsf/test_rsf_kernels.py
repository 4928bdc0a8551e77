"""The numba kernels against their plain-Python source, and the defining properties of the
stick and slip roots (first crossing, nothing skipped)."""
from __future__ import annotations

import math
import os
import subprocess
import sys

import numpy as np
import pytest

import rsf
from rsf import _kernels as K

PLAIN = K.kernel_namespace(jit=False)


def _model(k0=0.3):
    m = rsf.SpringSlider(k0=k0)
    return m, m.law.kernel_params


@pytest.mark.parametrize("k0, V", [(0.3, 0.1), (0.3, 0.05), (0.01, 1.0), (1e-4, 500.0)])
def test_compiled_kernels_match_plain_python(k0, V):
    m, p = _model(k0)
    lo, hi = m.law.weakening_bounds()
    lip = m.K + hi
    for theta in (m.Dc / V * 1.3, m.Dc / V * 0.7, 1e-3, 10.0):
        h0 = -0.01
        for sup in (math.nan, m.law.concave_sup):
            a = K.stick_end(p, h0, theta, m.k0 * V, m.Dc, 1e9, 0.0, sup)
            b = PLAIN["stick_end"](p, h0, theta, m.k0 * V, m.Dc, 1e9, 0.0, sup)
            assert a[1] == b[1] and a[0] == pytest.approx(b[0], rel=1e-13)
        a = K.slip_end(p, 0.02, theta, m.K, m.Dc, lip, 1e-250 * m.Dc)
        b = PLAIN["slip_end"](p, 0.02, theta, m.K, m.Dc, lip, 1e-250 * m.Dc)
        assert a[1] == b[1] and a[0] == pytest.approx(b[0], rel=1e-13)
        assert K.decide(p, theta, m.K, V, m.Dc) == PLAIN["decide"](p, theta, m.K, V, m.Dc)
    y = np.array([0.3, 1.0, 2.0])
    c = np.array([m.K, V, m.Dc, V, m.Dc / 5.0, 1e-8, 10.0, math.log(V), 1.0, 0.0])
    ya, yb = np.zeros(3), np.zeros(3)
    K.slide_rhs(y, ya, p, c)
    PLAIN["slide_rhs"](y, yb, p, c)
    np.testing.assert_allclose(ya, yb, rtol=1e-14)
    # every state law (aging, slip, PRZ, Nagata), radiation damping and a second state
    for code, eta, cb, b2 in [(0, 0, 0, 0), (1, 0, 0, 0), (2, 0, 0, 0), (3, 0, 0.5, 0),
                              (0, 0.1, 0, 0), (3, 0.1, 0.5, 0), (1, 0, 0, 0.01), (2, 0.1, 0, 0.01)]:
        y = np.array([0.4, -0.2, 0.0, 0.0, 0.0, 0.3])
        c = np.array([m.K, V, m.Dc, 1e-3, code, V, 0.0, 0.0, 1e-8, 0.0, 1e9, 1e300,
                      eta, cb, b2, 0.7, 0.1, 0.02 * (code == 1), 0.5])
        ya, yb = np.zeros(6), np.zeros(6)
        K.rs_rhs(y, ya, p, c)
        PLAIN["rs_rhs"](y, yb, p, c)
        np.testing.assert_allclose(ya, yb, rtol=1e-14)


def _phi(m, theta):
    return float(m.law.mu_ss(m.Dc / theta))


@pytest.mark.parametrize("k0, V, theta0", [(0.3, 0.1, 0.5), (0.3, 0.19, 0.2), (0.01, 1.0, 1e-40),
                                            (0.01, 0.01, 2.0), (1e-4, 1000.0, 1e-200)])
def test_stick_end_is_the_first_crossing(k0, V, theta0):
    m, p = _model(k0)
    sigma0 = _phi(m, theta0) - 1e-3
    t, flag = K.stick_end(p, sigma0 - _phi(m, theta0), theta0, m.k0 * V, m.Dc, 1e12, 0.0, math.nan)
    t2, flag2 = K.stick_end(p, sigma0 - _phi(m, theta0), theta0, m.k0 * V, m.Dc, 1e12, 0.0,
                            m.law.concave_sup)
    assert flag == flag2 == K.FOUND
    assert t2 == pytest.approx(t, rel=1e-12)     # the march and the convex bracket agree
    h = lambda tt: sigma0 + m.k0 * V * tt - _phi(m, theta0 + tt)  # noqa: E731 (numpy side)
    assert abs(h(t)) < 1e-13
    grid = np.concatenate([np.geomspace(1e-12 * max(t, 1e-300), t, 2000)[:-1], t * np.linspace(0, 1, 2000)[1:-1]])
    assert max(h(tt) for tt in grid) < 1e-13


@pytest.mark.parametrize("k0, theta0, gap", [(0.3, 0.5, 0.0), (0.3, 0.6, 0.01), (0.01, 6.0, 0.0),
                                              (1e-4, 0.06, 0.0)])
def test_slip_end_is_the_first_landing(k0, theta0, gap):
    m, p = _model(k0)
    lo, hi = m.law.weakening_bounds()
    sigma0 = _phi(m, theta0) + gap
    s, flag = K.slip_end(p, gap, theta0, m.K, m.Dc, m.K + hi, 1e-250 * m.Dc)
    assert flag in (K.FOUND, K.FLOOR)
    # g(s) = sigma0 - K s - phi(theta0 e^-s) > 0 before the landing, 0 at it
    mu_inf = m.law.mu_ref
    phi = lambda ss: mu_inf + float(K.dphi(p, theta0, -ss, m.Dc)) + (_phi(m, theta0) - mu_inf)  # noqa: E731
    g = lambda ss: sigma0 - m.K * ss - phi(ss)  # noqa: E731
    if flag == K.FOUND:
        assert abs(g(s)) < 1e-13
    grid = np.linspace(0, min(s, 650.0), 4001)[1:-1]
    assert min(g(x) for x in grid) > -1e-14
    if flag == K.FLOOR:     # the slip levels off at the large-velocity friction
        assert sigma0 - m.K * s == pytest.approx(m.law.mu_ref, abs=1e-12)


def test_decide_follows_the_signs_of_N_and_D():
    m, p = _model(0.3)
    V = 0.1
    for theta in np.geomspace(1e-4, 1e4, 81):
        u = m.Dc / theta
        w = float(m.law.weakening(u))
        N, D = m.K * V - u * w, m.K - w
        expect = K.STICK if N < 0 else (K.SLIDE if D > 0 else K.SLIP)
        if abs(N) > 1e-9 and abs(D) > 1e-9:
            assert K.decide(p, theta, m.K, V, m.Dc) == expect


def test_law_eval_dispatch_rejects_unknown_code():
    assert all(math.isnan(x) for x in K.law_eval(1.0, np.array([99.0])))


_COMPILE_ONCE = """
import math, numba, rsf
from rsf import _kernels as K
m = rsf.SpringSlider(k0=0.3)
p = m.law.kernel_params
K.stick_end(p, -0.01, 1.0, m.k0 * 0.1, m.Dc, 1e9, 0.0, math.nan)
K.slip_end(p, 0.02, 1.0, m.K, m.Dc, m.K + m.law.weakening_bounds()[1], 1e-250 * m.Dc)
K.decide(p, 1.0, m.K, 0.1, m.Dc)
for kernel in (K.phase_fn, K.phase_dfn, K.brentq, K.first_root):
    kinds = {sig[0] for sig in kernel.signatures}
    assert kinds == {numba.int64}, (kernel.__name__, kinds)
"""


def test_root_kernels_compile_once_for_both_phases(tmp_path):
    # stick_end and slip_end hand phase_fn's kind as int64: a Python literal 0 or 1 made
    # numba compile phase_fn, phase_dfn, brentq and first_root once per literal.  In a fresh
    # process with an empty numba cache, as on a first run: with the callers loaded from a
    # warm cache (any run after the first) their callees are never typed in the process, and
    # have no signatures to look at
    done = subprocess.run([sys.executable, "-c", _COMPILE_ONCE], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)})
    assert done.returncode == 0, done.stderr
