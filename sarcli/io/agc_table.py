"""A pass's receiver-attenuation table (dB per line) and where a raw block sits in it.

Radarsat-1 records the receiver attenuation of every echo line in the line's header; the Cumming &
Wong programs read it into a table for the whole pass (``AGC_attenuation_values.mat``:
``nom_attenuation``, 19432 values in whole dB for the Vancouver pass), while their raw blocks keep only
the 4-bit samples. A block of N lines starting at line L of the pass (1-based) had the attenuation
``table[L - 1 : L - 1 + N]``; undoing it multiplies line m by 10**(a_m / 20)
(``RawProduct.line_gain``).

Alignment. The attenuation changes in single-line steps of 1 dB; the recorded line power follows each
step within one line, while the scene changes the line power smoothly (a target is seen for a whole
aperture, hundreds of lines). With p(m) = 10 log10 of the mean power of line m and first differences
dp(m) = p(m) - p(m-1), a start index s (0-based) predicts

    dp(m) = -g * da_s(m) + e(m),     da_s(m) = table[s + m] - table[s + m - 1],

g the output dB per input dB (1 for a linear receiver; below 1 where the 4-bit quantizer saturates:
0.5-0.9 on the Vancouver blocks) and e the line-to-line change of scene and speckle. With e white of
standard deviation sigma (estimated robustly as 1.4826 x the median absolute deviation of dp: a few
steps do not move it), the least-squares g is c_s / E_s with c_s = sum(-da_s dp), E_s = sum(da_s^2),
and the matched-filter statistic

    z_s = c_s / (sigma sqrt(E_s))

is N(0, 1) at a wrong start (no relation between the block and that stretch of the table) and
g sqrt(E_s) / sigma at the right one. Two starts s1, s2 compare by the likelihood ratio
ln Lambda = (z_s1^2 - z_s2^2) / 2 (Gaussian e, g fitted at each: one free parameter on either side).
Measured on the six Vancouver blocks: over all wrong starts the z have mean 0.00 and standard
deviation 1.05-1.26 (the Gaussian model is close to honest; alternating steps 8 lines apart, as in the
Squamish stretch of the pass, make the tail heavier: largest wrong z 4.3-10), at the right start
12.8-26.8.

Decision rules (:func:`check_start`, :func:`best_start`): a start is *confirmed* when its z is at least
:data:`Z_MATCH` (8) and at least half the best z of the table; it is *contradicted* when another start
reaches :data:`Z_MATCH` and the given one explains less than half of it (z_given < z_best / 2);
without any start reaching :data:`Z_MATCH` (a block inside a stretch of constant attenuation, or with
one step only) the table cannot place the block (it can still be applied at a start given otherwise).
``first_line = "auto"`` takes the best start when it reaches :data:`Z_MATCH` and every start more than
2 lines away stays below half of it (:data:`SEPARATION`; the six Vancouver blocks: ratio 2.5-2.9).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.io

from sarcli.errors import FormatError, MissingFileError
from sarcli.io.linepower import line_power_db

Z_MATCH = 8.0
SEPARATION = 2.0
TABLE_VARIABLE = "nom_attenuation"


def read_agc_table(path: str | os.PathLike, variable: str | None = None) -> np.ndarray:
    """The attenuation table (float64 dB, one value per line of the pass) from a MATLAB 5 file: the
    variable ``variable``, else ``nom_attenuation``, else the only variable. One FormatError line for
    a missing, unreadable or non-numeric table."""
    path = Path(path)
    if not path.is_file():
        raise MissingFileError(f"{path}: no such file")
    try:
        mat = scipy.io.loadmat(path, squeeze_me=True)
    except NotImplementedError:
        raise FormatError(f"{path}: MATLAB v7.3 (HDF5) AGC tables are not supported; save with -v7") from None
    except (scipy.io.matlab.MatReadError, ValueError, TypeError, OSError, EOFError) as e:
        raise FormatError(f"{path}: not a readable MATLAB AGC table ({e})") from None
    names = [k for k in mat if not k.startswith("__")]
    name = variable or (TABLE_VARIABLE if TABLE_VARIABLE in names else (names[0] if len(names) == 1 else None))
    if name is None or name not in mat:
        raise FormatError(f"{path}: no AGC variable {variable or TABLE_VARIABLE!r} "
                          f"(variables: {', '.join(names) or 'none'})")
    a = np.asarray(mat[name])
    if a.ndim != 1 or a.size < 2 or not (np.issubdtype(a.dtype, np.integer) or np.issubdtype(a.dtype, np.floating)):
        raise FormatError(f"{path}: AGC variable '{name}' is not a 1-D numeric table (shape {a.shape}, {a.dtype})")
    a = a.astype(np.float64)
    if not np.all(np.isfinite(a)):
        raise FormatError(f"{path}: AGC variable '{name}' contains NaN or inf")
    return a


@dataclass(frozen=True)
class AgcAlignment:
    """The matched-filter statistic of every start index (module docstring).

    ``z`` and ``gain`` (output dB per input dB) per 0-based start index into the table (0 where the
    table is constant over the block: no information); ``sigma_db`` the robust standard deviation of
    the line-to-line power differences."""

    z: np.ndarray
    gain: np.ndarray
    sigma_db: float

    @property
    def best(self) -> int:
        """0-based start index with the largest z."""
        return int(np.argmax(self.z))

    def runner_up(self, start: int, exclude: int = 2) -> float:
        """Largest z more than ``exclude`` lines from ``start`` (0 if there is none)."""
        others = np.r_[self.z[:max(0, start - exclude)], self.z[start + exclude + 1:]]
        return float(others.max()) if others.size else 0.0

    def log_likelihood_ratio(self, s1: int, s2: int) -> float:
        """ln of the likelihood ratio of start s1 against s2, (z1^2 - z2^2) / 2."""
        return 0.5 * (float(self.z[s1]) ** 2 - float(self.z[s2]) ** 2)


def align(echo: np.ndarray, table: np.ndarray) -> AgcAlignment:
    """z and gain of every start index of a block ``echo`` (lines, samples) in ``table`` (dB per line)."""
    n = echo.shape[0]
    t = np.asarray(table, np.float64)
    if n < 3:
        raise FormatError(f"a block of {n} line(s) cannot be aligned with an AGC table (needs 3 or more)")
    if t.size < n:
        raise FormatError(f"the AGC table has {t.size} lines, fewer than the block's {n}")
    dp = np.diff(line_power_db(echo))
    sigma = 1.4826 * float(np.median(np.abs(dp - np.median(dp))))
    if not sigma > 0:
        sigma = float(np.std(dp)) or 1.0
    da = np.diff(t)  # da[k] = t[k+1] - t[k]; start s predicts dp[j] = -g da[s + j]
    c = np.correlate(-da, dp, mode="valid")
    e = np.convolve(da**2, np.ones(n - 1), mode="valid")
    info = e > 0
    safe = np.where(info, e, 1.0)
    z = np.where(info, c / (sigma * np.sqrt(safe)), 0.0)
    g = np.where(info, c / safe, 0.0)
    return AgcAlignment(z, g, sigma)


def check_start(al: AgcAlignment, start: int) -> str:
    """``confirmed`` | ``contradicted`` | ``undecided`` for a 0-based start (module docstring)."""
    z_best = float(al.z[al.best])
    z = float(al.z[start])
    if z >= Z_MATCH and z >= 0.5 * z_best:
        return "confirmed"
    if z_best >= Z_MATCH and z < 0.5 * z_best:
        return "contradicted"
    return "undecided"


def best_start(al: AgcAlignment) -> int | None:
    """The 0-based start the table picks on its own, or None when no start is clear enough."""
    b = al.best
    z = float(al.z[b])
    if z >= Z_MATCH and al.runner_up(b) * SEPARATION <= z:
        return b
    return None
