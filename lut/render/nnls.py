"""Non-negative least squares (numpy only: scipy is not in Blender).

``nnls(a, b)`` solves min ‖a x - b‖ with x >= 0 by the active-set method of
Lawson and Hanson (*Solving Least Squares Problems*, 1974, ch. 23);
``nnls_gram(G, g)`` the same problem given its normal equations G = aᵀa,
g = aᵀb, which is how the closure fit (``lut.render.fitting``) meets it: many small
problems (a handful of unknowns) over hundreds of rows."""

from __future__ import annotations

import numpy as np


def solve_spd(a, b):
    """x with a x = b for a batch of small symmetric positive definite
    systems, a (..., n, n) and b (..., n): the Cholesky factor L (a = L Lᵀ,
    numpy's batched ``linalg.cholesky``), then L y = b and Lᵀ x = y by
    substitution, n numpy steps each over the whole batch (Golub and Van
    Loan, *Matrix Computations*, 4th ed., 2013, secs. 3.1 and 4.2).  numpy's
    batched ``linalg.solve`` would call LAPACK's getrs once per matrix, whose
    triangular solves wake a threaded BLAS's (OpenBLAS) threads on each
    call: with the closure fit's thousands of tiny systems that cost 20 s of
    a 1.5 s fit on a 2-core machine with other work running; the Cholesky
    factorisation of a small matrix stays on one thread.  Where a matrix is
    not numerically positive definite, the whole batch is solved by
    Gaussian elimination without pivoting instead (``_eliminate``)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    try:
        lower = np.linalg.cholesky(a)
    except np.linalg.LinAlgError:
        return _eliminate(a, b)
    n = a.shape[-1]
    y = np.empty(np.broadcast_shapes(a.shape[:-1], b.shape))
    for k in range(n):
        y[..., k] = (b[..., k] - np.einsum("...j,...j->...", lower[..., k, :k], y[..., :k])) / lower[..., k, k]
    x = y
    for k in range(n - 1, -1, -1):
        x[..., k] = (y[..., k] - np.einsum("...j,...j->...", lower[..., k + 1 :, k], x[..., k + 1 :])) / lower[
            ..., k, k
        ]
    return x


def _eliminate(a, b):
    """``solve_spd`` by Gaussian elimination without pivoting, which is
    stable for symmetric positive definite matrices (Golub and Van Loan,
    sec. 4.2) and finishes on semi-definite ones."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    batch = np.broadcast_shapes(a.shape[:-2], b.shape[:-1])
    a = np.array(np.broadcast_to(a, (*batch, *a.shape[-2:])))
    x = np.array(np.broadcast_to(b, (*batch, b.shape[-1])))
    n = a.shape[-1]
    for k in range(n - 1):
        factor = a[..., k + 1 :, k] / a[..., k, k, None]
        a[..., k + 1 :, k + 1 :] -= factor[..., :, None] * a[..., k, None, k + 1 :]
        x[..., k + 1 :] -= factor * x[..., k, None]
    for k in range(n - 1, -1, -1):
        tail = np.einsum("...j,...j->...", a[..., k, k + 1 :], x[..., k + 1 :])
        x[..., k] = (x[..., k] - tail) / a[..., k, k]
    return x


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
            z[idx] = solve_spd(sub, rhs[idx])
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


def nnls_gram_batch(gram, rhs, upper=None, max_iter=None, start=None):
    """``nnls_gram`` for a batch of independent problems at once: gram
    (B, n, n), rhs (B, n) -> x (B, n).  The same active-set iteration, every
    problem stepping together with its own passive set (a masked system:
    variables outside the set get an identity row and a zero right-hand
    side), so the cost is a few batched solves rather than B Python loops.
    ``upper`` (n,): variables above it are fixed at it and the rest solved
    again, until none is above (the bound-constrained optimum when the
    bound binds on few variables, as for Mix Shader factors).  ``start``
    (B, n): a guess whose positive entries form the first passive sets (a
    warm start: the solution of a problem with one variable fewer, as in
    forward selection, takes one or two steps instead of one per variable)."""
    gram, rhs = np.asarray(gram, dtype=float), np.asarray(rhs, dtype=float)
    b, n = rhs.shape
    fixed = np.zeros((b, n), dtype=bool)
    x = _batch_active_set(gram, rhs, fixed, max_iter, start)
    if upper is None:
        return x
    upper = np.broadcast_to(np.asarray(upper, dtype=float), (n,))
    for _ in range(n):
        over = (x > upper) & ~fixed
        if not over.any():
            break
        fixed |= over
        fixed_x = np.where(fixed, upper, 0.0)
        x = np.where(
            fixed, upper, _batch_active_set(gram, rhs - np.einsum("bij,bj->bi", gram, fixed_x), fixed, max_iter)
        )
    return x


def _batch_active_set(gram, rhs, excluded, max_iter=None, start=None):
    b, n = rhs.shape
    scale = np.maximum(np.abs(gram).reshape(b, -1).max(axis=1), 1e-300)
    tol = 1e-12 * scale * max(n, 1)
    eye = np.eye(n)
    max_iter = max_iter or 3 * n + 3

    def solve(passive, rows):
        """The passive set's least squares solution of the problems ``rows``
        (the others, finished, are left at zero: not solved again)."""
        p = passive[rows]
        mask = p[:, :, None] & p[:, None, :]
        sub = np.where(mask, gram[rows], 0.0) + np.where(p, 1e-13 * scale[rows, None], 1.0)[:, :, None] * eye
        z = np.zeros((b, n))
        z[rows] = np.where(p, solve_spd(sub, np.where(p, rhs[rows], 0.0)), 0.0)
        return z

    x = np.zeros((b, n))
    passive = np.zeros((b, n), dtype=bool)
    active = np.ones(b, dtype=bool)

    def settle(pending, retire=True):
        """Lawson and Hanson's inner loop: solve on the passive sets of the
        ``pending`` problems, stepping back toward feasibility (dropping the
        variables that reach zero) until each solution is positive;
        ``retire``: a problem left with no passive variable is done."""
        nonlocal x, passive
        for _inner in range(3 * n + 3):
            z = solve(passive, np.flatnonzero(pending))
            neg = passive & (z <= 0)
            bad = pending & neg.any(axis=1)
            good = pending & ~bad
            x[good] = z[good]
            if not bad.any():
                break
            ratio = np.where(neg, x / np.maximum(x - z, 1e-300), np.inf)
            alpha = np.where(bad, ratio.min(axis=1), 0.0)[:, None]
            x = np.where(bad[:, None], x + alpha * (z - x), x)
            passive &= ~(bad[:, None] & (x <= tol[:, None] / scale[:, None]))
            x = np.where(passive, x, 0.0)
            if retire:
                active[:] &= passive.any(axis=1) | ~bad
            pending = bad & active & passive.any(axis=1)

    if start is not None:
        # A feasible start (x >= 0, zero outside its passive set) made the
        # least squares solution of its passive set before the outer loop.
        passive = (np.asarray(start, dtype=float) > 0) & ~excluded
        x = np.where(passive, np.asarray(start, dtype=float), 0.0)
        if passive.any():
            settle(passive.any(axis=1), retire=False)
    for _ in range(max_iter):
        w = rhs - np.einsum("bij,bj->bi", gram, x)
        candidates = np.where(passive | excluded, -np.inf, w)
        j = np.argmax(candidates, axis=1)
        active &= candidates[np.arange(b), j] > tol
        if not active.any():
            break
        passive[np.flatnonzero(active), j[active]] = True
        settle(active.copy())  # the problems whose passive set is not yet feasible
    return x
