"""The vestibular models' compiled core: parallel first-order sections, stepped per sample or over a trace.

A model discretised for one time step (:class:`washbench.perception.vestibular.DiscreteModel`) is a sum of
first-order sections ``x_i[k] = phi_i x_i[k-1] + b_i0 u[k] + b_i1 u[k-1]``, output ``y[k] = sum_i x_i[k]``
(summed in section order). :func:`sections_step` is that one step; :func:`sections_apply` runs it over whole
columns, and the studies' evaluation kernel (:mod:`washbench.analysis.evaluate`) calls the same step per sample,
so both give the same bits. A filter starts in the steady state of its first sample: ``x_i = s_i u[0]`` with
``s_i`` the section's DC gain.
"""

from __future__ import annotations

import numpy as np

from washbench.numerics.jit import njit, prange


@njit(cache=True, inline="always")
def sections_init(steady, x, u0):
    """Set the section states ``x`` (S,) to the steady state of a constant input ``u0``."""
    for i in range(x.shape[0]):
        x[i] = steady[i] * u0


@njit(cache=True, inline="always")
def sections_step(b, phi, x, u_prev, u):
    """One sample: advance the section states ``x`` (S,) with input ``u`` (previous ``u_prev``); return y."""
    y = 0.0
    for i in range(x.shape[0]):
        x[i] = phi[i] * x[i] + b[i, 0] * u + b[i, 1] * u_prev
        y += x[i]
    return y


@njit(cache=True, parallel=True)
def sections_apply(b, phi, steady, u):
    """Filter every column of ``u`` (N, m) along axis 0, each starting in its first sample's steady state.

    Returns (N, m) in column-major order (each column contiguous, as the metrics and tables read them).
    """
    n, m = u.shape
    yt = np.empty((m, n))
    for j in prange(m):
        x = np.empty(phi.shape[0])
        sections_init(steady, x, u[0, j])
        u_prev = u[0, j]
        for k in range(n):
            yt[j, k] = sections_step(b, phi, x, u_prev, u[k, j])
            u_prev = u[k, j]
    return yt.T


@njit(cache=True)
def sections_run(b, phi, x, u_prev, u):
    """Filter the next samples ``u`` (N, m) from the section states ``x`` (S, m) and previous inputs ``u_prev``
    (m,), both advanced in place (chunk by chunk: :class:`washbench.perception.vestibular.PerceptionStream`).

    The same step as :func:`sections_apply`, so a trace fed in chunks gives the bits it gives whole.
    """
    n, m = u.shape
    y = np.empty((n, m))
    xs = np.empty(phi.shape[0])
    for j in range(m):
        for i in range(xs.shape[0]):
            xs[i] = x[i, j]
        up = u_prev[j]
        for k in range(n):
            y[k, j] = sections_step(b, phi, xs, up, u[k, j])
            up = u[k, j]
        for i in range(xs.shape[0]):
            x[i, j] = xs[i]
        u_prev[j] = up
    return y


@njit(cache=True, parallel=True)
def sections_apply_from(b, phi, steady, u, u0):
    """:func:`sections_apply` with each column starting in the steady state of ``u0[j]`` (m,) instead of its
    first sample (the input held at ``u0`` before the trace, ramping to ``u[0]`` over the first step)."""
    n, m = u.shape
    yt = np.empty((m, n))
    for j in prange(m):
        x = np.empty(phi.shape[0])
        sections_init(steady, x, u0[j])
        u_prev = u0[j]
        for k in range(n):
            yt[j, k] = sections_step(b, phi, x, u_prev, u[k, j])
            u_prev = u[k, j]
    return yt.T
