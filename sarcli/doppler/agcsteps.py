"""Receiver-gain (AGC) steps recovered from the echo itself, for products that do not record them.

A Radarsat-1 receiver changes its attenuation in discrete steps between lines to keep the quantizer
loaded. When the product carries the attenuation per line (CEOS, our simulator) ``RawProduct.calibrated``
undoes it; the MATLAB extraction of the Vancouver block does not, and its line power jumps by
+0.6..0.7 dB in a single line at lines 289, 397, 477, 605, 751, 966 and by -0.6..-0.7 dB at 1325 and 1515
while drifting smoothly in between. Left in, such a step re-weights every target whose aperture it
crosses (the part after the step counts 15 % more) and pulls the centroid of the blocks that contain it.

Detector. p(m) = 10 log10 of the mean power of line m over all range samples (a gain step is common to
every range). Around each line m a window of ``w`` lines on either side is fitted by one common slope
and two levels, p = a + b (t - m) + d [t >= m]; d is the step (dB), with its standard error from the fit
residuals. A candidate is a local maximum of |d| (suppression over +-w lines) with |d| above both
``min_step_db`` and ``n_sigma`` standard errors. It is accepted only if it is SHARP: the line-to-line
jump p(m) - p(m-1) has the sign of d, at least half its size, and exceeds ``n_jump`` robust standard
deviations of all line-to-line differences. That rejects the scene: the raw line power is the scene
convolved with the two-way azimuth pattern (hundreds of lines), and a few dominant scatterers beating
against each other modulate it over several lines (a narrow simulated swath with a bright town gave
1.1-1.5 dB level changes with single-line jumps of at most 1.7 robust sigma; the Vancouver steps jump
by 3-6 sigma in one line).

Undo. The step is measured again per range group of ``group_samples`` samples and undone there: the
output step depends on the quantizer's saturation (on the Vancouver block 1.1-1.4 dB in the dark near
range, 0.4-0.8 dB in the bright far range for what is presumably one 1 dB attenuation step), and the
correlation sums weight the output power.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sarcli.io.linepower import group_power, power_db


@dataclass
class GainSteps:
    """Detected steps: ``lines`` (first line after each step), ``db`` (step of the whole-swath power,
    dB), ``db_groups`` (n_steps, n_groups) the step per range group, whose first samples are
    ``group_start`` (ascending, starting at 0)."""

    lines: np.ndarray
    db: np.ndarray
    db_groups: np.ndarray
    group_start: np.ndarray

    def as_list(self) -> list[list[float]]:
        """[[line, dB], ...] for reports."""
        return [[int(m), round(float(d), 3)] for m, d in zip(self.lines, self.db, strict=True)]

    def profile_db(self, n_lines: int) -> np.ndarray:
        """(n_groups, n_lines) cumulative gain per group and line, 0 before the first step."""
        prof = np.zeros((self.group_start.size, n_lines))
        for m, dg in zip(self.lines, self.db_groups, strict=True):
            prof[:, m:] += dg[:, None]
        return prof


def step_statistic(p: np.ndarray, w: int) -> tuple[np.ndarray, np.ndarray]:
    """(d, sigma_d) per line: the step of the two-level, common-slope fit over [m - w, m + w); 0/inf
    where the window does not fit."""
    n = p.size
    d = np.zeros(n)
    sd = np.full(n, np.inf)
    if n < 2 * w or w < 3:
        return d, sd
    tc = np.arange(w, dtype=np.float64) - 0.5 * (w - 1)
    sxx = 2.0 * np.sum(tc**2)
    win = np.lib.stride_tricks.sliding_window_view(p, 2 * w)  # row k: lines k .. k + 2w - 1, m = k + w
    left, right = win[:, :w], win[:, w:]
    ml, mr = left.mean(axis=1, keepdims=True), right.mean(axis=1, keepdims=True)
    b = ((left - ml) @ tc + (right - mr) @ tc)[:, None] / sxx
    res2 = np.sum((left - ml - b * tc) ** 2, axis=1) + np.sum((right - mr - b * tc) ** 2, axis=1)
    m = np.arange(w, n - w + 1)
    d[m] = (mr - ml - b * w)[:, 0]  # the two means sit w lines apart
    sd[m] = np.sqrt(res2 / (2 * w - 3) * (2.0 / w + w**2 / sxx))
    return d, sd


def step_size(p: np.ndarray, m: int, lo: int, hi: int) -> float:
    """Step at line m of the two-level, common-slope fit of p over [lo, m) and [m, hi) (dB)."""
    left, right = p[lo:m], p[m:hi]
    tl, tr = np.arange(lo, m) - m, np.arange(m, hi) - m
    a = np.column_stack([np.r_[tl, tr], np.r_[np.zeros(tl.size), np.ones(tr.size)], np.ones(tl.size + tr.size)])
    coef, *_ = np.linalg.lstsq(a, np.r_[left, right], rcond=None)
    return float(coef[1])


def detect_gain_steps(echo: np.ndarray, w: int = 16, min_step_db: float = 0.25, n_sigma: float = 6.0,
                      n_jump: float = 3.0, group_samples: int = 256, size_lines: int = 64) -> GainSteps:
    """Gain steps of ``echo`` (module docstring). Detection uses +-``w`` lines (none in an echo shorter
    than 2 w lines); each accepted step's size is then fitted over up to ``size_lines`` lines on either
    side, bounded by its neighbouring steps."""
    n_s = echo.shape[1]
    g0 = np.arange(0, n_s, max(1, group_samples), dtype=np.int64)
    if g0.size > 1 and n_s - g0[-1] < group_samples // 2:
        g0 = g0[:-1]  # a short last group joins the previous one
    edges = np.append(g0, n_s)
    group_p = group_power(echo, edges)  # one pass for the whole-line and the per-group powers
    p = power_db(group_p @ np.diff(edges).astype(np.float64) / n_s)
    if p.size < 2 * w:
        return GainSteps(np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 1)), np.zeros(1, np.int64))
    d, sd = step_statistic(p, w)
    jump = np.diff(p, prepend=p[0])
    dj = np.diff(p)
    jump_sigma = 1.4826 * np.median(np.abs(dj - np.median(dj))) if dj.size else np.inf
    score = np.where(np.abs(d) > np.maximum(min_step_db, n_sigma * sd), np.abs(d), 0.0)
    lines = []
    while np.any(score > 0):
        m = int(np.argmax(score))
        score[max(0, m - w):m + w] = 0.0
        near = np.arange(max(1, m - 2), min(p.size, m + 3))
        k = int(near[np.argmax(np.abs(jump[near]))])  # the step line itself (the fit peak may be off by one)
        if np.sign(jump[k]) == np.sign(d[m]) and abs(jump[k]) >= 0.5 * abs(d[m]) and abs(jump[k]) > n_jump * jump_sigma:
            lines.append(k)
    lines = np.array(sorted(set(lines)), dtype=np.int64)
    bounds = np.r_[0, lines, p.size]
    spans = [(max(bounds[i], m - size_lines), min(bounds[i + 2], m + size_lines)) for i, m in enumerate(lines)]
    dg = np.zeros((lines.size, g0.size))
    for j in range(g0.size):
        pg = power_db(group_p[:, j])
        dg[:, j] = [step_size(pg, m, lo, hi) for m, (lo, hi) in zip(lines, spans, strict=True)]
    db = np.array([step_size(p, m, lo, hi) for m, (lo, hi) in zip(lines, spans, strict=True)])
    return GainSteps(lines, db, dg, g0)


def undo_gain_steps(echo: np.ndarray, steps: GainSteps, in_place: bool = False) -> np.ndarray:
    """The echo with each group's step profile divided out (the first segment keeps its level): a
    complex64 copy, or with ``in_place`` the ``echo`` itself, changed, when it is a writable complex64
    array (a full scene's echo is 1.1 GB: the copy doubled the Doppler estimate's memory)."""
    reuse = in_place and echo.dtype == np.complex64 and echo.flags.writeable
    out = echo if reuse else np.array(echo, np.complex64)
    if steps.lines.size == 0:
        return out
    prof = steps.profile_db(out.shape[0])
    edges = np.append(steps.group_start, out.shape[1])
    for j in range(steps.group_start.size):
        out[:, edges[j]:edges[j + 1]] *= (10.0 ** (-prof[j] / 20.0)).astype(np.float32)[:, None]
    return out
