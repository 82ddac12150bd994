"""Non-negative least squares (numpy only: scipy is not in Blender).

``nnls(a, b)`` solves min ‖a x - b‖ with x >= 0 by the active-set method of
Lawson and Hanson (*Solving Least Squares Problems*, 1974, ch. 23);
``nnls_gram(G, g)`` the same problem given its normal equations G = aᵀa,
g = aᵀb, which is how the closure fit (``lut.fitting``) meets it: many small
problems (a handful of unknowns) over hundreds of rows."""

from __future__ import annotations

import numpy as np


def nnls(a, b, tol=None, max_iter=None):
    """Non-negative least squares min ‖a x - b‖, x >= 0."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return nnls_gram(a.T @ a, a.T @ b, tol=tol, max_iter=max_iter)


def nnls_gram(gram, rhs, tol=None, max_iter=None, upper=None):
    """min ½xᵀGx - gᵀx over x >= 0 (and x <= ``upper`` where given: a
    bound is applied by fixing the variables that exceed it and solving for
    the rest, once), G symmetric positive semi-definite: Lawson and
    Hanson's active set method on the normal equations."""
    gram, rhs = np.asarray(gram, dtype=float), np.asarray(rhs, dtype=float)
    n = rhs.size
    scale = max(float(np.abs(gram).max()) if gram.size else 0.0, 1e-300)
    tol = tol if tol is not None else 1e-12 * scale * max(n, 1)
    ridge = 1e-13 * scale
    max_iter = max_iter or 3 * n + 3
    x = np.zeros(n)
    passive = np.zeros(n, dtype=bool)
    w = rhs - gram @ x
    for _ in range(max_iter):
        if passive.all() or w[~passive].max() <= tol:
            break
        j = int(np.argmax(np.where(passive, -np.inf, w)))
        passive[j] = True
        for _inner in range(3 * n + 3):
            z = np.zeros(n)
            idx = np.flatnonzero(passive)
            sub = gram[np.ix_(idx, idx)] + ridge * np.eye(idx.size)
            z[idx] = np.linalg.solve(sub, rhs[idx])
            if z[idx].min() > 0:
                x = z
                break
            neg = passive & (z <= 0)
            alpha = np.min(x[neg] / np.maximum(x[neg] - z[neg], 1e-300))
            x = x + alpha * (z - x)
            passive &= x > tol / scale
            x[~passive] = 0.0
            if not passive.any():
                break
        w = rhs - gram @ x
    if upper is not None:
        upper = np.broadcast_to(np.asarray(upper, dtype=float), x.shape)
        over = x > upper
        if over.any():
            x_fixed = np.where(over, upper, 0.0)
            free = np.flatnonzero(~over)
            x = x_fixed.copy()
            if free.size:
                sub_rhs = rhs[free] - gram[np.ix_(free, np.flatnonzero(over))] @ upper[over]
                x[free] = nnls_gram(gram[np.ix_(free, free)], sub_rhs, tol=tol, upper=upper[free])
    return x
