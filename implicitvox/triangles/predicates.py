"""Exact sign predicates on float inputs: a floating-point filter, then exact integers.

The two determinants the box-triangle test needs:

* ``det2_sign(a, b, p, q)`` = sign of ``(b0 - a0)(q1 - p1) - (b1 - a1)(q0 - p0)``
  (``orient2d`` when ``p`` is ``a``);
* ``orient3d_sign(a, b, c, d)`` = sign of ``det[b - a, c - a, d - a]``.

Each is evaluated in floats with Shewchuk's a-priori error bound
(J. R. Shewchuk, *Adaptive Precision Floating-Point Arithmetic and Fast
Robust Geometric Predicates*, 1997: ``ccwerrboundA = (3 + 16e)e`` and
``o3derrboundA = (7 + 56e)e`` times the permanent, ``e = 2**-53``); we use
the rounder ``4e`` and ``8e``. Where the float value does not clear the bound
(near-degenerate input), or under- or overflow could have spoiled it, the
determinant is recomputed exactly: every float is an integer times a power
of two, so scaling the inputs of one element by a common power of two gives
Python integers whose determinant has the same sign. That exact path works
on numpy object arrays (one numpy call per operation, no Python loop per
element) and runs only on the few uncertain elements.

The result is the sign of the determinant of the *given* floats, exactly.

Examples
--------
>>> import numpy as np
>>> a, b = np.array([[0.0, 0.0]]), np.array([[1.0, 1.0]])
>>> q = np.array([[0.1, 0.1]])      # 0.1 is not 1/10: exactly on the line y = x anyway
>>> int(det2_sign(a, b, a, q)[0])
0
>>> int(det2_sign(a, b, a, np.array([[0.5, 0.5 + 2.0**-53]]))[0])
1
"""
from __future__ import annotations

import numpy as np

__all__ = ["det2_sign", "orient3d_sign", "exact_integers", "FixedPlanes"]

_EPS = 2.0 ** -53
_DET2_BOUND = 4.0 * _EPS
_DET3_BOUND = 8.0 * _EPS
#: below this the float products may have underflowed: go exact
_TINY = 2.0 ** -900
#: products below this may have lost bits to underflow
_NORMAL = 2.0 ** -1000


def exact_integers(*columns: np.ndarray) -> list[np.ndarray]:
    """Columns of floats (each ``(n,)``) as object arrays of Python ints, each
    row scaled by the same power of two (so signs of homogeneous polynomials
    are kept)."""
    v = np.stack([np.asarray(c, dtype=np.float64) for c in columns])
    return list(_integers_at(v, _lowest_exponent(v, axis=0)))


def _lowest_exponent(values: np.ndarray, axis=None):
    """The least power of two ``e`` such that every float of ``values`` (along
    ``axis``; all of them when None) is an integer times ``2**e``, 0 where all
    are zero."""
    mant, expo = np.frexp(values)
    never = np.iinfo(np.int64).max
    expo = np.where(mant != 0, expo.astype(np.int64) - 53, never)
    low = expo.min(axis=axis)
    return np.where(low == never, 0, low)


def _integers_at(values: np.ndarray, low) -> np.ndarray:
    """Finite floats as an object array of Python ints, in units of ``2**low``
    (``low`` at most :func:`_lowest_exponent` of ``values``; an array of them
    broadcasts along the last axis)."""
    mant, expo = np.frexp(values)
    ints = (mant * 2.0 ** 53).astype(np.int64)            # exact: |mant| < 1
    shift = np.where(mant == 0, 0, expo.astype(np.int64) - 53 - low)
    return np.left_shift(ints.astype(object), shift.astype(object))


def _sign_objects(values: np.ndarray) -> np.ndarray:
    """Signs (-1, 0, 1) of an object array of Python ints, as int8."""
    if not len(values):
        return np.zeros(0, dtype=np.int8)
    return (values > 0).astype(np.int8) - (values < 0).astype(np.int8)


def det2_sign(a: np.ndarray, b: np.ndarray, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Sign (-1, 0, 1) of ``(b0 - a0)(q1 - p1) - (b1 - a1)(q0 - p0)`` per row.

    ``a, b, p, q`` are ``(n, 2)`` float arrays (or tuples of two ``(n,)``
    columns). Exact for all finite input.
    """
    a0, a1 = _columns(a)
    b0, b1 = _columns(b)
    p0, p1 = _columns(p)
    q0, q1 = _columns(q)
    with np.errstate(all="ignore"):
        left = (b0 - a0) * (q1 - p1)
        right = (b1 - a1) * (q0 - p0)
        det = left - right
        bound = _DET2_BOUND * (np.abs(left) + np.abs(right))
        sure = (np.abs(det) > bound) & (bound > _TINY) & np.isfinite(bound)
        sign = np.sign(det).astype(np.int8)
    unsure = np.flatnonzero(~sure)
    if len(unsure):
        cols = [np.broadcast_to(c, det.shape)[unsure] for c in (a0, a1, b0, b1, p0, p1, q0, q1)]
        A0, A1, B0, B1, P0, P1, Q0, Q1 = cols
        # both products exactly zero (axis-aligned input) without underflow: the sign is 0
        zero = (bound[unsure] == 0) & _no_tiny_factor(B0 - A0, Q1 - P1, B1 - A1, Q0 - P0)
        unsure, cols = unsure[~zero], [c[~zero] for c in cols]
    if len(unsure):
        A0, A1, B0, B1, P0, P1, Q0, Q1 = exact_integers(*cols)
        sign[unsure] = _sign_objects((B0 - A0) * (Q1 - P1) - (B1 - A1) * (Q0 - P0))
    return sign


def orient3d_sign(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Sign (-1, 0, 1) of ``det[b - a, c - a, d - a]`` per row of ``(n, 3)`` arrays.

    Positive when ``d`` lies on the side of the plane ``abc`` that
    ``(b - a) x (c - a)`` points to. Exact for all finite input.
    """
    with np.errstate(all="ignore"):
        bx, by, bz = (b[:, i] - a[:, i] for i in range(3))
        cx, cy, cz = (c[:, i] - a[:, i] for i in range(3))
        dx, dy, dz = (d[:, i] - a[:, i] for i in range(3))
        products = ((cy, dz), (cz, dy), (cz, dx), (cx, dz), (cx, dy), (cy, dx))
        p1, p2, p3, p4, p5, p6 = (u * v for u, v in products)
        det = bx * (p1 - p2) + by * (p3 - p4) + bz * (p5 - p6)
        perm = (np.abs(bx) * (np.abs(p1) + np.abs(p2)) + np.abs(by) * (np.abs(p3) + np.abs(p4))
                + np.abs(bz) * (np.abs(p5) + np.abs(p6)))
        bound = _DET3_BOUND * perm
        sure = (np.abs(det) > bound) & (bound > _TINY) & np.isfinite(bound)
        # an underflowed minor product would be amplified by the outer factor: go exact
        for (u, v), prod in zip(products, (p1, p2, p3, p4, p5, p6)):
            sure &= (np.abs(prod) >= _NORMAL) | (u == 0) | (v == 0)
        # all terms exactly zero without underflow: the sign is 0
        sure |= (perm == 0) & _no_tiny_factor(bx, by, bz, cx, cy, cz, dx, dy, dz)
        sign = np.sign(det).astype(np.int8)
    unsure = np.flatnonzero(~sure)
    if len(unsure):
        cols = [m[unsure, i] for m in (a, b, c, d) for i in range(3)]
        ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz = exact_integers(*cols)
        bx, by, bz = bx - ax, by - ay, bz - az
        cx, cy, cz = cx - ax, cy - ay, cz - az
        dx, dy, dz = dx - ax, dy - ay, dz - az
        exact = bx * (cy * dz - cz * dy) + by * (cz * dx - cx * dz) + bz * (cx * dy - cy * dx)
        sign[unsure] = _sign_objects(exact)
    return sign


class FixedPlanes:
    """``orient3d_sign(a, b, c, d)`` for fixed triangles ``(a, b, c)`` (each ``(t, 3)``)
    against many points ``d``: the triangles' 2 x 2 minors (the components of
    ``n = (b - a) x (c - a)``) and their permanents are computed once, so a point
    costs a difference and a dot product, ``n . (d - a)``.

    That is the determinant in Shewchuk's order with the roles of the three
    difference vectors turned (an outer factor times a minor, summed), so his
    bound holds as it is, against the permanent ``sum_i |d - a|_i (|b_j c_l| +
    |b_l c_j|)``: we use the same ``8e`` as :func:`orient3d_sign`. A triangle
    whose minor products may have underflowed, and any point the float value
    does not clear, go to :func:`orient3d_sign` itself: the sign is exact.

    Examples
    --------
    >>> import numpy as np
    >>> a, b, c = np.zeros((1, 3)), np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]])
    >>> planes = FixedPlanes(a, b, c)
    >>> planes.sign(np.array([0, 0, 0]), np.array([[0, 0, 2.0], [5, 7, 0], [0, 0, -1]])).tolist()
    [1, 0, -1]
    """

    def __init__(self, a: np.ndarray, b: np.ndarray, c: np.ndarray):
        self.a, self.b, self.c = a, b, c
        with np.errstate(all="ignore"):
            bx, by, bz = (b[:, i] - a[:, i] for i in range(3))
            cx, cy, cz = (c[:, i] - a[:, i] for i in range(3))
            pairs = ((by, cz), (bz, cy), (bz, cx), (bx, cz), (bx, cy), (by, cx))
            p1, p2, p3, p4, p5, p6 = (u * v for u, v in pairs)
            self.normal = np.stack([p1 - p2, p3 - p4, p5 - p6], axis=1)
            self.weight = np.stack([np.abs(p1) + np.abs(p2), np.abs(p3) + np.abs(p4),
                                    np.abs(p5) + np.abs(p6)], axis=1)
            ok = np.all(np.isfinite(self.weight), axis=1)
            for (u, v), prod in zip(pairs, (p1, p2, p3, p4, p5, p6)):
                ok &= (np.abs(prod) >= _NORMAL) | (u == 0) | (v == 0)
        self.filtered = ok
        #: per triangle, as rows: a (3), the normal (3), its weights (3) and
        #: "filtered" (0 or 1): one gather per query (rows stay contiguous)
        self._table = np.concatenate([a.T, self.normal.T, self.weight.T,
                                      ok[None, :].astype(np.float64)])
        #: the same per triangle, one row each ``(t, 10)``: for compiled loops
        self.rows = np.ascontiguousarray(self._table.T)

    def sign(self, which: np.ndarray, d: np.ndarray) -> np.ndarray:
        """Sign of ``orient3d(a[which], b[which], c[which], d)`` per row, exactly."""
        a0, a1, a2, n0, n1, n2, w0, w1, w2, filtered = np.take(self._table, which, axis=1)
        with np.errstate(all="ignore"):
            dx, dy, dz = d[:, 0] - a0, d[:, 1] - a1, d[:, 2] - a2
            det = n0 * dx + n1 * dy + n2 * dz
            np.abs(dx, out=dx)
            np.abs(dy, out=dy)
            np.abs(dz, out=dz)
            bound = _DET3_BOUND * (w0 * dx + w1 * dy + w2 * dz)
            sure = (np.abs(det) > bound) & (bound > _TINY) & np.isfinite(bound) & (filtered > 0)
            sign = np.sign(det).astype(np.int8)
        unsure = np.flatnonzero(~sure)
        if len(unsure):
            sign[unsure] = self._exact_sign(which[unsure], d[unsure])
        return sign

    def _exact_sign(self, which: np.ndarray, d: np.ndarray) -> np.ndarray:
        """The exact sign of ``n . (d - a)`` for the rows the float filter left open.

        All coordinates of the batch (the rows' points and their triangles'
        vertices) become Python integers at one common power of two; each
        distinct triangle's normal ``N`` and offset ``N . A`` are computed once,
        so a row costs three products and a difference of integers.
        """
        tris, row_tri = np.unique(which, return_inverse=True)
        a, b, c = self.a[tris], self.b[tris], self.c[tris]
        low = int(_lowest_exponent(np.concatenate([m.ravel() for m in (a, b, c, d)])))
        A, B, C, D = (_integers_at(m, low) for m in (a, b, c, d))
        U, V = B - A, C - A
        N = np.stack([U[:, 1] * V[:, 2] - U[:, 2] * V[:, 1],
                      U[:, 2] * V[:, 0] - U[:, 0] * V[:, 2],
                      U[:, 0] * V[:, 1] - U[:, 1] * V[:, 0]], axis=1)
        offset = (N * A).sum(axis=1)
        N = N[row_tri]
        det = N[:, 0] * D[:, 0] + N[:, 1] * D[:, 1] + N[:, 2] * D[:, 2] - offset[row_tri]
        return _sign_objects(det)


def _columns(v):
    if isinstance(v, tuple):
        return v
    return v[:, 0], v[:, 1]


def _no_tiny_factor(*values: np.ndarray) -> np.ndarray:
    """True where every value is zero or large enough that products cannot underflow."""
    ok = np.ones(values[0].shape, dtype=bool)
    for v in values:
        av = np.abs(v)
        ok &= (av == 0) | (av > 2.0 ** -300)
    return ok
