"""The tapes valid over the mesher's cells, evaluated many cells at a time.

The voxelization leaves each run of voxels with the tape pruned for it (Stolte
§2's subdivision, each box's tape shortened by its min/max choices). The
mesher asks each cell's tape for point values at its corners, interval value
and gradient enclosures over it, and the crossings on its edges. On the compiled
kernel those tapes are rows of one :class:`~implicitvox.eval.tape_pool.TapePool`,
and every cell runs on its own tape in one compiled call
(:func:`~implicitvox.eval.pool_gradients.pool_values`,
:func:`~implicitvox.eval.mean_value_kernels.pool_interval_gradients`,
:func:`~implicitvox.eval.pool_gradients.pool_crossings`: the same floats as each
tape built alone); a level-3 Menger sponge has thousands of such tapes, and
building each one and calling numpy on its few cells cost more than the
arithmetic. Otherwise (tapes of the array path, tapes pickled by worker
processes, a pool with operations the pool kernels do not run) the cells go to
their tapes one tape at a time (:func:`per_tape`).

Examples
--------
>>> import numpy as np, implicitvox as iv
>>> from implicitvox import x, y, z
>>> tapes = CellTapes([iv.compile(x * x + y * y + z * z - 1).tape])
>>> tapes.values(np.zeros(2, dtype=np.int64), np.array([0.0, 2.0]), np.zeros(2),
...              np.zeros(2)).tolist()
[-1.0, 3.0]
"""
from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from ..eval.interval import evaluate_intervals
from ..eval.mean_value import evaluate_interval_gradients
from ..eval.point import evaluate_points
from .edges import STEPS, crossings, unit_normals

__all__ = ["CellTapes", "per_tape", "CHUNK"]

#: rows per call on the per-tape path
CHUNK = 1 << 14


def per_tape(tapes: list, tid: np.ndarray, fn: Callable, *arrays: np.ndarray,
             chunk: int = CHUNK) -> tuple:
    """``fn(tape, *rows)`` over the rows of each tape (``tapes[tid[i]]`` is valid
    over row ``i``), in chunks of ``chunk`` rows; the outputs (a tuple of arrays,
    rows first) put back in row order. The pruned tapes of the voxelization
    (:attr:`implicitvox.octree.subdivide.Subdivision.tapes`) give the same
    values, enclosures and gradients as the whole tape over their octants, in
    fewer operations (:mod:`implicitvox.eval.pruning`)."""
    n = len(tid)
    order = np.argsort(tid, kind="stable")
    starts = np.searchsorted(tid[order], np.arange(len(tapes) + 1))
    outs: Optional[list] = None
    for t in range(len(tapes)):
        group = order[starts[t]:starts[t + 1]]
        for s in range(0, len(group), chunk):
            rows = group[s:s + chunk]
            got = fn(tapes[t], *(a[rows] for a in arrays))
            got = got if isinstance(got, tuple) else (got,)
            if outs is None:
                outs = [np.empty((n,) + np.shape(g)[1:], dtype=np.asarray(g).dtype) for g in got]
            for o, g in zip(outs, got):
                o[rows] = g
    if outs is None:
        got = fn(tapes[0], *(a[:0] for a in arrays))
        got = got if isinstance(got, tuple) else (got,)
        outs = [np.asarray(g) for g in got]
    return tuple(outs)


class CellTapes:
    """Tapes ``0 .. len - 1``, each valid over the cells that name it (see the module
    docstring).

    Parameters
    ----------
    tapes : list of Tape, optional
        The tapes (the per-tape path).
    pool : TapePool, optional
        With ``ids``: tape ``k`` is the pool's tape ``ids[k]``.
    ids : ndarray of int64, optional
    """

    def __init__(self, tapes: Optional[list] = None, pool: Any = None,
                 ids: Optional[np.ndarray] = None):
        self.pool = pool
        self.ids = None if ids is None else np.asarray(ids, dtype=np.int64)
        self._tapes = tapes
        if pool is not None:
            from ..eval.pool_gradients import takes_pool      # (loads Numba)
            self.compiled = takes_pool(pool) and not pool.undefined
        else:
            self.compiled = False

    @classmethod
    def of_runs(cls, runs: Any, default: Any) -> tuple["CellTapes", np.ndarray]:
        """The tapes of a subdivision's runs (:class:`implicitvox.octree.octants.TapeRuns`
        or a list of ``(count, tape)``), each pool tape once, and the tape of each run;
        ``default`` (a tape) when there are no runs."""
        pool, ids = getattr(runs, "pool", None), getattr(runs, "ids", None)
        if pool is not None and ids is not None and len(ids):
            unique, of_run = np.unique(ids, return_inverse=True)
            return cls(pool=pool, ids=unique), of_run.ravel().astype(np.int64)
        tapes = [t for _, t in runs] or [default]
        return cls(tapes), np.arange(len(runs), dtype=np.int64)

    def __len__(self) -> int:
        return len(self.ids) if self.ids is not None else len(self._tapes)

    @property
    def tapes(self) -> list:
        """The tapes as :class:`~implicitvox.eval.tape.Tape` objects (built on first use)."""
        if self._tapes is None:
            self._tapes = [self.pool.tape(int(i)) for i in self.ids]
        return self._tapes

    def _runs(self, tid: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Rows sorted by tape: ``(order, pool tape of each run, rows per run)``."""
        order = np.argsort(tid, kind="stable")
        sorted_tid = tid[order]
        starts = np.flatnonzero(np.diff(sorted_tid, prepend=-1)) if len(tid) else \
            np.zeros(0, dtype=np.int64)
        counts = np.diff(np.append(starts, len(tid)))
        return order, self.ids[sorted_tid[starts]], counts

    def values(self, tid: np.ndarray, xs: np.ndarray, ys: np.ndarray, zs: np.ndarray
               ) -> np.ndarray:
        """``f`` (float64) at points ``(xs[i], ys[i], zs[i])``, each on tape ``tid[i]``."""
        if self.compiled:
            from ..eval.pool_gradients import pool_values
            order, tapes, counts = self._runs(tid)
            out = np.empty(len(tid))
            out[order] = pool_values(self.pool, tapes, counts, xs[order], ys[order], zs[order])
            return out

        def one(tape, x, y, z):
            with np.errstate(all="ignore"):
                return np.broadcast_to(evaluate_points(tape, x, y, z), x.shape) \
                    .astype(np.float64)
        return per_tape(self.tapes, tid, one, xs, ys, zs)[0]

    def interval_gradients(self, tid: np.ndarray, lo: tuple, hi: tuple) -> tuple:
        """:func:`~implicitvox.eval.mean_value.evaluate_interval_gradients` over boxes
        ``lo, hi`` (three columns each), each on tape ``tid[i]``: ``(vlo, vhi, glo,
        ghi, valid)``, the gradients ``(3, n)``."""
        lo, hi = np.stack(lo), np.stack(hi)
        if self.compiled:
            from ..eval.mean_value_kernels import pool_interval_gradients
            order, tapes, counts = self._runs(tid)
            got = pool_interval_gradients(self.pool, tapes, counts, lo[:, order],
                                          hi[:, order])
            outs = []
            for g in got:
                o = np.empty_like(g)
                o[..., order] = g
                outs.append(o)
            return tuple(outs)

        def one(tape, lo_rows, hi_rows):
            with np.errstate(all="ignore"):
                vlo, vhi, glo, ghi, valid = evaluate_interval_gradients(
                    tape, tuple(lo_rows.T), tuple(hi_rows.T))
            n = len(lo_rows)
            return (np.broadcast_to(np.asarray(vlo, dtype=np.float64), (n,)),
                    np.broadcast_to(np.asarray(vhi, dtype=np.float64), (n,)),
                    np.broadcast_to(np.asarray(glo, dtype=np.float64), (3, n)).T,
                    np.broadcast_to(np.asarray(ghi, dtype=np.float64), (3, n)).T,
                    np.broadcast_to(np.asarray(valid), (n,)))
        vlo, vhi, glo, ghi, valid = per_tape(self.tapes, tid, one, lo.T, hi.T)
        return vlo, vhi, glo.T, ghi.T, valid

    def intervals(self, tid: np.ndarray, lo: tuple, hi: tuple) -> tuple[np.ndarray, np.ndarray]:
        """Enclosures ``(flo, fhi)`` of ``f`` over boxes ``lo, hi``, each on tape
        ``tid[i]`` (:func:`~implicitvox.eval.interval.evaluate_intervals`, float64)."""
        if self.compiled:
            vlo, vhi, _, _, _ = self.interval_gradients(tid, lo, hi)
            return vlo, vhi

        def one(tape, lo_rows, hi_rows):
            with np.errstate(all="ignore"):
                flo, fhi = evaluate_intervals(tape, tuple(lo_rows.T), tuple(hi_rows.T))
            n = len(lo_rows)
            return (np.broadcast_to(np.asarray(flo, dtype=np.float64), (n,)),
                    np.broadcast_to(np.asarray(fhi, dtype=np.float64), (n,)))
        return per_tape(self.tapes, tid, one, np.stack(lo, 1), np.stack(hi, 1))

    def crossings(self, tid: np.ndarray, a: np.ndarray, b: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
        """:func:`~implicitvox.meshing.edges.crossings` of edges ``a[i] -> b[i]``, each on
        tape ``tid[i]``: points and unit normals ``(n, 3)``."""
        if self.compiled:
            from ..eval.pool_gradients import pool_crossings, pool_gradients
            order, tapes, counts = self._runs(tid)
            points = pool_crossings(self.pool, tapes, counts, a[order], b[order], STEPS)
            _, g = pool_gradients(self.pool, tapes, counts, *points.T)
            p, n = np.empty_like(points), np.empty_like(points)
            p[order], n[order] = points, unit_normals(g)
            return p, n
        return per_tape(self.tapes, tid, lambda tape, x, y: crossings(tape, x, y), a, b)
