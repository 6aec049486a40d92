"""kernels.update against an independent numpy step, over every route and flag.

One CG step (docs/models.md §2.2) written out in numpy from the rules of
``kernels._point_event``: free points step to ``p - tau/sigma·t``, leave the free set when
the step takes them out of ``[0, p_max]`` (direction zeroed unless ``keep_mask``), and
constrained points that should be free (unloaded and penetrating, or at ``p_max`` and open)
move by ``-tau·g`` and join (projected onto ``[0, p_max]`` with ``keep_mask``); with
``with_u``, ``u -= tau/sigma·r`` after the gaps are read. The grid's chunks are built to
take each of update's routes: no events; a few clipped points with violators before,
between and after them and in blocks of their own; more clipped points than the slots and
no violator; more violators than the slots; exactly the slots' worth; fewer violators than
the slots but more events; a short last chunk whose last block is short.

Tolerances: pressures 1e-13 relative (the same products in another association), sums
1e-12 (summed in another order), masks, directions and counts exact.
"""

import itertools

import numpy as np
import pytest

from amontons.contact import kernels as K

S = K.SLOTS


def _reference(p, u, r, t, h, m, pmax, bounded, sigma, d, tau, keep_mask, with_u):
    n = p.size
    step = tau / sigma
    ub = pmax if bounded else np.full(n, np.inf)
    q = p - step * t
    pn = sigma * q
    g = sigma * u - h - d  # gap read BEFORE u -= step*r
    free = m != 0
    low, high = free & (pn < 0), free & (pn > ub)
    clip = low | high
    cval = np.where(low, -pn, np.where(high, ub - pn, 0.0))
    pn = np.where(low, 0.0, np.where(high, ub, pn))
    notfree = ~free | clip
    sj = ((pn <= 0) & (g < 0) & (pn < ub)) | ((pn >= ub) & (g > 0) & (pn > 0))
    join = notfree & sj
    added = -tau * g
    joined = pn + added
    if keep_mask:
        jc = np.clip(joined, 0.0, ub)
        added = np.where(join, jc - pn, added)
        joined = jc
    pn = np.where(join, joined, pn)
    q = np.where(clip | join, pn / sigma, q)
    m_new = m.copy()
    t_new = t.copy()
    if not keep_mask:
        m_new[clip] = 0
        t_new[clip] = 0.0
        m_new[join] = 1
    u_new = u - step * r if with_u else u.copy()
    recs = []  # per point in index order: clip record then join record
    for i in np.flatnonzero(clip | join):
        if clip[i]:
            recs.append((i, cval[i]))
        if join[i]:
            recs.append((i, added[i]))
    at_bound = q[sigma * q >= ub].sum() if bounded else 0.0
    pen = np.abs(g[join]).max() if join.any() else 0.0
    return q, m_new, t_new, u_new, clip, join, recs, at_bound, pen


def _make(bounded, seed=0):
    """Chunks with chosen (clips, violators) patterns; last chunk short (last block short)."""
    rng = np.random.default_rng(seed)
    nch_full = 7
    n = nch_full * K.CHUNK + 300
    sigma, d, tau = 1.3, 0.0, 1e-3
    step = tau / sigma
    m = (rng.random(n) < 0.5).astype(np.uint8)
    pmax = (2.0 + rng.random(n)) if bounded else np.full(n, np.inf)
    p = np.where(m == 1, (0.3 + 0.5 * rng.random(n)) / sigma, 0.0)
    if bounded:  # a third of the constrained points at the bound
        atb = (m == 0) & (rng.random(n) < 0.33)
        p[atb] = pmax[atb] / sigma
        bad = atb & (sigma * p < pmax)
        p[bad] = np.nextafter(p[bad], np.inf)
    else:
        atb = np.zeros(n, bool)
    t = np.where(m == 1, 0.01 * rng.normal(size=n), 0.0)
    u = rng.normal(size=n)
    r = 0.01 * rng.normal(size=n)
    # gaps: free points +-1 at random, constrained ones not violating
    gap = np.where(rng.random(n) < 0.5, 1.0, -1.0)
    gap[(m == 0) & ~atb] = 1.0
    gap[atb] = -1.0
    free_ix = np.flatnonzero(m)
    con_ix = np.flatnonzero(m == 0)

    def clip_pts(ix, upper=False, rejoin=None):
        for j, i in enumerate(ix):
            up = bounded and (upper if upper is not None else j % 2)
            if up:
                t[i] = (p[i] * sigma - pmax[i] - 0.5) / (sigma * step)
            else:
                t[i] = (p[i] * sigma + 0.5) / (sigma * step)
            rj = (j % 2 == 0) if rejoin is None else rejoin
            gap[i] = (1.0 if up else -1.0) * (0.7 if rj else -0.7)
            # with_u: u -= step*r would flip the gap's sign if it were read afterwards
            r[i] = 2 * gap[i] / (sigma * step) / sigma

    def viol(ix):
        for i in ix:
            gap[i] = 0.5 if atb[i] else -0.5

    def pick(arr, lo, hi, k, rng_pick=False):
        c = arr[(arr >= lo) & (arr < hi)]
        return c[:k] if not rng_pick else rng.choice(c, k, replace=False)

    C, B = K.CHUNK, K.SCAN
    # chunk 0: no events
    # chunk 1: 3 clips in block 0 (one rejoining), violators before, between and after them
    #          in block 0, a violator alone in block 5, one in the chunk's last point region
    lo = C
    fb = pick(free_ix, lo + 20, lo + 200, 3)
    clip_pts(fb)
    viol(pick(con_ix, lo, fb[0], 1))
    viol(pick(con_ix, fb[0], fb[1], 1))
    viol(pick(con_ix, fb[2], lo + B, 1))
    viol(pick(con_ix, lo + 5 * B, lo + 6 * B, 1))
    viol(pick(con_ix, lo + C - 40, lo + C, 1))
    # chunk 2: many clips (> SLOTS), no violators
    lo = 2 * C
    clip_pts(np.sort(pick(free_ix, lo, lo + C, 3 * S, True)))
    # chunk 3: a few clips and more violators than SLOTS (sentinel)
    lo = 3 * C
    clip_pts(pick(free_ix, lo + 1000, lo + 2000, 2))
    viol(np.sort(pick(con_ix, lo, lo + C, S + 5, True)))
    # chunk 4: violators only (3), in three blocks
    lo = 4 * C
    for b in (0, 7, 63):
        viol(pick(con_ix, lo + b * B, lo + (b + 1) * B, 1))
    # chunk 5: exactly SLOTS violators and one clip
    lo = 5 * C
    viol(np.sort(pick(con_ix, lo, lo + C, S, True)))
    clip_pts(pick(free_ix, lo + 5000, lo + 6000, 1))
    # chunk 6: SLOTS - 1 violators and 3 clips (events > SLOTS: records dropped)
    lo = 6 * C
    viol(np.sort(pick(con_ix, lo, lo + C, S - 1, True)))
    clip_pts(pick(free_ix, lo + 300, lo + 400, 3), rejoin=False)
    # last (short) chunk: a clip and a violator in the short last block, violator last
    lo = 7 * C
    clip_pts(pick(free_ix, lo + 260, lo + 300, 1))
    last_con = pick(con_ix, lo + 256, lo + 300, 10)
    viol(last_con[-1:])
    h = sigma * u - d - gap
    return dict(p=p, u=u, r=r, t=t, h=h, m=m, pmax=pmax, sigma=sigma, d=d, tau=tau, n=n)


@pytest.mark.parametrize(
    "bounded,keep_mask,with_u,inplace,record_max",
    list(
        itertools.product(
            [False, True], [False, True], [False, True], [False, True], [-1, 0, 3, S, 1000]
        )
    ),
)
def test_update_against_numpy(bounded, keep_mask, with_u, inplace, record_max):
    D = _make(bounded)
    n, sigma, d, tau = D["n"], D["sigma"], D["d"], D["tau"]
    p, u, r, t, h, m, pmax = (D[k].copy() for k in ("p", "u", "r", "t", "h", "m", "pmax"))
    pm = pmax if bounded else np.full(1, np.inf)
    nch = K.n_chunks(n)
    viol = np.zeros(nch, dtype=np.int64)
    vidx = np.zeros((nch, S), dtype=np.int64)
    vg = np.zeros((nch, S))
    # through kernel_threads, as the solver calls them: it loads the kernels from numba's
    # cache (a cold one is filled by a child process first, .kernel_cache)
    with K.kernel_threads(1):
        K.direction(u, sigma, h, m, t.copy(), d, 0.0, 0.0, p, pm, bounded, viol, vidx, vg)
    ref = _reference(p, u, r, t, h, m, pmax, bounded, sigma, d, tau, keep_mask, with_u)
    q, m_ref, t_ref, u_ref, clip, join, recs, at_b, pen_ref = ref
    chunk = np.arange(n) // K.CHUNK
    ev = np.bincount(chunk[clip], minlength=nch) + np.bincount(chunk[join], minlength=nch)
    # the test's design
    assert list(ev[[0]]) == [0] and ev[2] > S and ev[6] > S and viol[3] > S
    assert viol[5] == S and viol[1] == 5

    idx = np.full((nch, S), -7, dtype=np.int64)
    val = np.zeros((nch, S))
    counts = np.zeros((nch, 2), dtype=np.int64)
    pp = p.copy()
    pn = pp if inplace else np.full(n, np.nan)
    uu = u.copy()
    mm, tt = m.copy(), t.copy()
    with K.kernel_threads(1):
        total, pen, at_bound, complete = K.update(
            pp, pn, uu, r, tt, h, mm, pm, bounded, sigma, d, tau, viol, idx, val, counts,
            keep_mask, with_u, vidx, vg, record_max,
        )  # fmt: skip
    np.testing.assert_allclose(pn, q, rtol=1e-13, atol=1e-300)
    assert np.array_equal(mm, m_ref)
    assert np.array_equal(tt, t_ref)
    np.testing.assert_allclose(uu, u_ref, rtol=1e-14, atol=1e-15)
    if not inplace:
        assert np.array_equal(pp, p)
    assert np.array_equal(counts[:, 0], np.bincount(chunk[clip], minlength=nch))
    assert np.array_equal(counts[:, 1], np.bincount(chunk[join], minlength=nch))
    assert total == pytest.approx(q.sum(), rel=1e-12)
    assert at_bound == pytest.approx(at_b, rel=1e-12, abs=0)
    assert pen == pytest.approx(pen_ref, rel=1e-14)
    limit = min(record_max, S)
    ok = bool(np.all(ev <= max(limit, 0)))
    # never claims complete records when a chunk dropped some
    if complete:
        assert np.all(ev <= S)
    assert complete == ok
    # records: a chunk within the limit lists its events in index order, a point's clip
    # before its join
    for c in range(nch):
        if ev[c] > max(limit, 0):
            continue  # the caller takes u afresh: these records are not used
        exp = [x for x in recs if x[0] // K.CHUNK == c]
        k = min(len(exp), S)
        got = list(zip(idx[c, :k].tolist(), val[c, :k].tolist(), strict=True))
        assert [g[0] for g in got] == [e[0] for e in exp[:k]], c
        np.testing.assert_allclose([g[1] for g in got], [e[1] for e in exp[:k]], rtol=1e-12)
