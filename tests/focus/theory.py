"""Independent theory for the tests: the continuous impulse response of a spectral window.

IRF(x) = integral_{-1/2}^{1/2} W(u) cos(2 pi u x) du (x in resolution cells 1/B; W symmetric, so the
IRF is real). Nulls are its sign changes; IRW = width where IRF^2 = peak^2/2; PSLR = largest |IRF| beyond
the first nulls; ISLR = energy beyond the first nulls out to ``extent`` null distances over the energy
between them. Computed by trapezoid quadrature, independently of sarcli.focus.quality.
"""

from __future__ import annotations

import numpy as np


def window_values(name: str, u: np.ndarray) -> np.ndarray:
    if name == "rect":
        return np.ones_like(u)
    if name == "hamming":
        return 0.54 + 0.46 * np.cos(2 * np.pi * u)
    if name == "kaiser:2.5":
        return np.i0(2.5 * np.sqrt(np.clip(1 - (2 * u) ** 2, 0, None))) / np.i0(2.5)
    raise ValueError(name)


def irf_theory(name: str, extent: float = 20.0) -> dict:
    u = np.linspace(-0.5, 0.5, 2001)
    w = window_values(name, u)
    x = np.arange(0, 60, 1 / 256)
    irf = np.trapezoid(w[None, :] * np.cos(2 * np.pi * u[None, :] * x[:, None]), u, axis=1)
    p = irf**2
    i = np.nonzero(np.diff(np.sign(irf)))[0][0]
    null = x[i] + irf[i] / (irf[i] - irf[i + 1]) * (x[i + 1] - x[i])
    j = np.nonzero(p < 0.5 * p[0])[0][0]
    half = x[j - 1] + (p[j - 1] - 0.5 * p[0]) / (p[j - 1] - p[j]) * (x[j] - x[j - 1])
    main = x <= null
    side = (x > null) & (x <= extent * null)
    # one-sided integrals (the IRF is even)
    e_main = np.trapezoid(p[main], x[main])
    e_side = np.trapezoid(p[side], x[side])
    return {"irw": 2 * half, "pslr_db": 10 * np.log10(p[x > null].max() / p[0]),
            "islr_db": 10 * np.log10(e_side / e_main), "null": null}
