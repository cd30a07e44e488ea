"""Standard deviations of SSI-cov poles: pyOMA-2's first-order propagation, sized for video.

pyOMA-2 (``pyoma2.functions.ssi``) estimates the covariance of the block Hankel matrix H from
``nb`` data blocks (``build_hank(..., calc_unc=True)``: each block's Hankel minus the whole
record's, scaled so that ``T T^T`` is the covariance of vec H) and propagates it to each pole's
frequency and damping through the SVD, the shift equation and the eigenproblem
(Döhler & Mevel 2013, ``SSI_poles(..., calc_unc=True)``). This module evaluates the same
equations with two changes, both checked against ``SSI_poles`` itself in
``tests/test_oma_uncertainty.py``:

* The Kronecker products ``kron(I, u^T) T`` and ``kron(v^T, I) T`` are evaluated as
  contractions of the blocks' Hankel differences: ``SSI_poles`` forms them as dense matrices
  of (block rows x channels)^3 entries, 3 GB each for the training window's 60 block rows x 12
  channels, where the contractions need none.
* The sensitivities of the singular vectors are computed for every order up to ``order_max``,
  whatever ``order_step``: ``SSI_poles`` fills them only at every ``step``-th singular vector
  and leaves the others zero, which drops their share of the variance when ``step > 1``.

Several records of one system (one camera under each wind) are identified from the mean of
their Hankel matrices; their blocks are independent, so the mean's covariance square root is
their ``T`` side by side over the number of records (``combine_blocks``).
"""

from __future__ import annotations

import numpy as np
from scipy import linalg


def block_count(n_samples: int, block_rows: int, block_seconds: float, fs: float) -> int:
    """The number of data blocks ``nb`` for a record: as many blocks of ``block_seconds`` as
    the Hankel matrix's ``N = n_samples - 2 block_rows + 1`` columns hold, at least 2.

    Args:
        n_samples: samples in the record.
        block_rows: the Hankel matrix's block rows.
        block_seconds: the shortest block, s.
        fs: sampling rate, Hz.

    Returns:
        nb.
    """
    n = int(n_samples) - 2 * int(block_rows) + 1
    return max(2, int(n // max(1, int(round(block_seconds * fs)))))


def combine_blocks(ts: list[np.ndarray]) -> np.ndarray:
    """Covariance square root of the mean of independent records' Hankel matrices.

    Args:
        ts: each record's ``T`` [L, nb_i] from ``build_hank(..., calc_unc=True)`` (same L).

    Returns:
        [L, sum nb_i]: ``T T^T = (1/R^2) sum_i T_i T_i^T``.
    """
    return np.concatenate(ts, axis=1) / len(ts)


def _hankel_blocks(T: np.ndarray, rows: int, cols: int) -> np.ndarray:
    """[nb, rows, cols]: each column of T (vec of a Hankel difference, column-major) as a matrix."""
    nb = T.shape[1]
    return T.T.reshape(nb, cols, rows).transpose(0, 2, 1)


def _commute(Q: np.ndarray, n: int) -> np.ndarray:
    """The commutation matrix P_nn applied to Q [n*n, nb] (vec of each n x n matrix transposed)."""
    return Q.reshape(n, n, -1).transpose(1, 0, 2).reshape(n * n, -1)


def pole_std(
    H: np.ndarray,
    T: np.ndarray,
    Obs: np.ndarray,
    AA: list[np.ndarray],
    n_channels: int,
    order_max: int,
    order_step: int,
    dt: float,
    freq: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Standard deviations of every pole's frequency and damping ratio.

    Args:
        H: [(p+1) l, q r] the block Hankel matrix (``build_hank``; p + 1 = q = block rows).
        T: [(p+1) q l r, nb] its covariance square root (``build_hank`` / ``combine_blocks``).
        Obs: [(p+1) l, order_max] the observability matrix (``SSI_fast``).
        AA: state matrices per order tried (``SSI_fast``).
        n_channels: l.
        order_max: the highest model order.
        order_step: orders tried in steps of this.
        dt: sample interval, s.
        freq: [P, O] the poles' frequencies from ``SSI_poles`` (NaN: no pole there; its
            standard deviations stay NaN).

    Returns:
        ``(freq_std [P, O] Hz, zeta_std [P, O])``.
    """
    l = int(n_channels)  # noqa: E741 (the paper's symbol)
    A_rows, B_cols = H.shape
    q = A_rows // l  # block rows (p + 1 = q)
    p = q - 1
    nb = T.shape[1]
    dH = _hankel_blocks(T, A_rows, B_cols)  # [nb, (p+1) l, q r]
    U, S, VT = np.linalg.svd(H, full_matrices=False)
    Un, Vn = U[:, :order_max], VT.T[:, :order_max]
    HtH = H.T @ H
    O1 = Obs[: p * l]  # S1 Obs
    O2 = Obs[l:]  # S2 Obs
    X1 = np.zeros((order_max, order_max, nb))  # column j: (S1 Obs)^T S1 J_j
    X2 = np.zeros_like(X1)  # (S2 Obs)^T S1 J_j
    X3 = np.zeros_like(X1)  # (S1 Obs)^T S2 J_j
    X4 = np.zeros((order_max, l, nb))  # first block row of J_j
    for j in range(order_max):  # every singular vector (see the module's note)
        s, u, v = S[j], Un[:, j], Vn[:, j]
        Kj = np.eye(B_cols) - HtH / s**2
        Kj[-1] += 2 * v
        Ti1 = np.einsum("kab,a->bk", dH, u)  # kron(I_qr, u^T) T   [q r, nb]
        Ti2 = np.einsum("kab,b->ak", dH, v)  # kron(v^T, I) T      [(p+1) l, nb]
        a = Ti2 - np.outer(u, u @ Ti2)
        b = Ti1 - np.outer(v, v @ Ti1)
        rhs = (H.T / s) @ a + b
        rhs[-1] -= u @ a
        Bab = a + (H / s) @ np.linalg.solve(Kj, rhs)  # Bi1 @ [a; b] (Eq. 29)
        J = np.outer(u, v @ Ti1) / (2 * np.sqrt(s)) + Bab / np.sqrt(s)  # Eq. 34  [(p+1) l, nb]
        X1[:, j] = O1.T @ J[: p * l]
        X2[:, j] = O2.T @ J[: p * l]
        X3[:, j] = O1.T @ J[l:]
        X4[j] = J[:l]
    f_std = np.full(freq.shape, np.nan)
    z_std = np.full(freq.shape, np.nan)
    for n_i, nn in enumerate(range(0, order_max + 1, order_step)):
        if nn == 0 or n_i >= freq.shape[1] or not np.isfinite(freq[:, n_i]).any():
            continue
        A = AA[n_i]
        lam_d, l_vec, r_vec = linalg.eig(A, left=True)
        lam_c = np.log(lam_d) / dt
        Oup = O1[:, :nn]
        OO = np.linalg.pinv(Oup.T @ Oup)
        Q1 = X1[:nn, :nn].reshape(nn * nn, nb, order="F")
        Q2 = X2[:nn, :nn].reshape(nn * nn, nb, order="F")
        Q3 = X3[:nn, :nn].reshape(nn * nn, nb, order="F")
        PnQ1 = _commute(Q1, nn) + Q1
        PnQ23 = _commute(Q2, nn) + Q3
        for jj in np.flatnonzero(np.isfinite(freq[: lam_d.size, n_i])):
            Y = (-lam_d[jj] * PnQ1 + PnQ23).reshape(nn, nn, nb)
            Qi = np.einsum("m,mik->ik", r_vec[:, jj], Y)  # kron(r^T, I) (...)  Eq. 44
            lc, ld = lam_c[jj], lam_d[jj]
            M1 = np.array([[1 / (2 * np.pi), 0], [0, 1 / abs(lc) ** 2]])
            M2 = np.array([[lc.real, lc.imag], [-(lc.imag**2), lc.real * lc.imag]])
            M3 = np.array([[ld.real, ld.imag], [-ld.imag, ld.real]])
            Jfx = (M1 @ M2 @ M3) / (dt * abs(ld) ** 2 * abs(lc))
            chi = np.conj(l_vec[:, jj])
            JaohT = (chi @ OO @ Qi) / (chi @ r_vec[:, jj])  # Eq. 43
            Ufx = Jfx @ np.vstack([JaohT.real, JaohT.imag])  # Eq. 42
            cov = Ufx @ Ufx.T
            f_std[jj, n_i] = np.sqrt(cov[0, 0])
            z_std[jj, n_i] = np.sqrt(cov[1, 1])
    return f_std, z_std
