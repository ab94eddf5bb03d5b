"""State space of a transfer function, as ``scipy.signal.tf2ss`` gives it, in numpy.

Importing ``scipy.signal`` (for this one function) took 1.3 s of every process that ran an optimal or MPC washout
or the bound (it imports ``scipy.stats`` and parses the docstrings of its array-API wrappers), more than the
washout's own start-up; the formulas are a few lines (scipy's ``signal/_lti_conversion.py``, ``tf2ss`` after
``normalize``), so they are written here. The same operations in the same order: the matrices are scipy's bit for
bit (``tests/test_statespace.py``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def tf2ss(num: Sequence[float] | np.ndarray, den: Sequence[float] | np.ndarray) -> tuple[np.ndarray, ...]:
    """(A (n, n), B (n, 1), C (1, n), D (1, 1)) of the proper single-input single-output ``num(s) / den(s)``
    (coefficients in descending powers of s, any consistent units): the controllable canonical form of
    ``scipy.signal.tf2ss``. Leading zeros are dropped as scipy drops them (in the numerator, coefficients within
    1e-14 of zero once divided by the denominator's first). Raises ValueError for an improper function, an empty
    one, a zero denominator or a static gain (no state)."""
    den_a = np.trim_zeros(np.atleast_1d(np.asarray(den, dtype=np.float64)), "f")
    num_a = np.atleast_1d(np.asarray(num, dtype=np.float64))
    if den_a.ndim != 1 or num_a.ndim != 1 or den_a.size == 0 or num_a.size == 0:
        raise ValueError("tf2ss: num and den must be 1-D, not empty, with a non-zero denominator")
    n = den_a.size - 1
    if n == 0:
        raise ValueError("tf2ss: a static gain has no state")
    num_a, den_a = num_a / den_a[0], den_a / den_a[0]
    kept = np.flatnonzero(np.abs(num_a) > 1e-14)
    num_a = num_a[kept[0] if kept.size else num_a.size - 1 :]  # leading (near-)zeros dropped, one kept: scipy's
    if num_a.size > n + 1:
        raise ValueError("tf2ss: improper transfer function (numerator of higher order than the denominator)")
    num_a = np.concatenate([np.zeros(n + 1 - num_a.size), num_a])
    d = np.array([[num_a[0]]])
    a = np.zeros((n, n))
    a[0, :] = -den_a[1:]
    a[1:, :-1] += np.eye(n - 1)
    b = np.zeros((n, 1))
    b[0, 0] = 1.0
    c = (num_a[1:] - num_a[0] * den_a[1:]).reshape(1, n)
    return a, b, c, d
