"""Derived GB-SAR system parameters: [LeeGBSAR-II-2007, Table 1], the DF range limit (eq. 11-12) and the
azimuth resolution of regions I-IV (eq. 22-45).

Notation as in the paper: f_c centre frequency, B_R bandwidth, N_R frequencies, df = B_R/(N_R-1),
X rail length, dx rail step, N_x stops, L_x antenna azimuth length, lam = c/f_c.
Fixed typos / choices (also in the module docs of the focusers):

* ``N_x = X/dx + 1`` (Table 1 prints ``- 1``; 4 m / 5 cm gives 81 stops).
* Range pixel: the DFT of ``N_Rfft`` bins spaced ``df`` gives bins ``c/(2*N_Rfft*df)`` apart; Table 1's
  ``c/(2*B_Rfft)`` with ``B_Rfft = (N_Rfft-1)*df`` is that value to 0.05 % (both are reported).
* ``R_max = c/(4*df)``: the IFFT covers ``c/(2*df)``; the paper keeps the positive-time half.
* The quadratic term of eq. 6-7 is ``R0^2/(2*Rc^3)`` (printed with R0 and Rc mixed).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from sarcli.errors import SarcliError
from sarcli.model.constants import C_LIGHT


def next_pow2(n: float) -> int:
    """Smallest power of two >= n (and >= 1)."""
    n = max(1.0, float(n))
    return 1 << math.ceil(math.log2(n) - 1e-12)


def df_min_range(wavelength_m: float, rail_length_m: float, antenna_length_m: float,
                 criterion_rad: float = math.pi / 4) -> float:
    """Eq. 12: ``R0 >= (pi X^2/(2 lam)) |(1+(lam/(2 L_x))^2)^(-3/2) - 1| / dphi_crit``.

    From eq. 11, the deramp error ``(2 pi/(lam R0)) |(R0/Rc)^3 - 1| x^2`` is largest at the rail
    ends ``x = X/2`` and at the half-beam edge ``xc = lam R0/(2 L_x)`` where ``R0/Rc = (1+(lam/(2L_x))^2)^(-1/2)``.
    """
    if criterion_rad <= 0:
        raise SarcliError("the DF phase-error criterion must be > 0 rad")
    a = (1.0 + (wavelength_m / (2 * antenna_length_m)) ** 2) ** -1.5 - 1.0
    return math.pi * rail_length_m ** 2 / (2 * wavelength_m) * abs(a) / criterion_rad


def df_phase_error(wavelength_m: float, r0: np.ndarray, xc: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Eq. 11: deramp phase error (rad) of the Rc ~ R0 approximation at rail position x."""
    rc = np.hypot(r0, xc)
    return 2 * np.pi / (wavelength_m * r0) * np.abs((r0 / rc) ** 3 - 1.0) * np.asarray(x) ** 2


@dataclass
class System:
    """[LeeGBSAR-II-2007, Table 1] for one configuration (SI units; None where undefined)."""

    center_frequency_hz: float
    bandwidth_hz: float
    n_r: int
    wavelength_m: float
    rail_length_m: float
    rail_step_m: float | None
    rail_uniform: bool
    n_x: int
    antenna_length_azimuth_m: float
    beamwidth_rad: float
    time_resolution_s: float | None
    range_resolution_m: float | None
    frequency_step_hz: float | None
    t_max_s: float | None
    r_max_m: float
    n_rfft: int
    b_rfft_hz: float | None
    range_pixel_m: float | None
    range_pixel_paper_m: float | None
    image_max_range_m: float
    n_xfft_df: int
    n_xfft_rd: int | None
    x_fft_df_m: float | None
    x_fft_rd_m: float | None
    du_df_per_m: float | None
    du_rd_per_m: float | None
    df_azimuth_pixel_per_rc: float | None
    df_azimuth_width_per_rc: float | None
    rd_azimuth_pixel_m: float | None
    rd_azimuth_width_m: float | None
    doppler_rate_coefficient: float
    beam_length_coefficient: float
    phase_coefficient_rad_per_m: float
    memory_df_bytes: int
    memory_rd_bytes: int | None
    raw_bytes: int
    df_min_range_m: float
    df_criterion_rad: float

    def as_dict(self) -> dict:
        return asdict(self)


def build_system(frequency: np.ndarray, rail_position: np.ndarray, antenna_length_m: float,
                 max_range_m: float | None = None, criterion_rad: float = math.pi / 4) -> System:
    """Derive Table 1 from a sweep, rail stops and the antenna azimuth length.

    ``max_range_m`` is the image extent Rc used by the RD rule ``N_xfft >= lam Rc/(2 dx^2) + 1``
    (default R_max). Memory is ``N_Rfft * N_xfft * 8`` bytes (complex64), as in the paper.
    """
    f = np.asarray(frequency, np.float64)
    x = np.asarray(rail_position, np.float64)
    n_r, n_x = int(f.size), int(x.size)
    fc = 0.5 * (f[0] + f[-1])
    bw = float(f[-1] - f[0])
    lam = C_LIGHT / fc
    if n_r > 1:
        dfreq = bw / (n_r - 1)
        dres, dt = C_LIGHT / (2 * bw), 1.0 / bw
        tmax, rmax = 1.0 / (2 * dfreq), C_LIGHT / (4 * dfreq)
    else:
        dfreq = dres = dt = tmax = None
        rmax = math.inf
    n_rfft = next_pow2(n_r)
    b_rfft = (n_rfft - 1) * dfreq if dfreq else None
    pix = C_LIGHT / (2 * n_rfft * dfreq) if dfreq else None
    pix_paper = C_LIGHT / (2 * b_rfft) if b_rfft else None
    rail_len = float(x[-1] - x[0]) if n_x > 1 else 0.0
    steps = np.diff(x)
    dx = float(np.median(steps)) if n_x > 1 else None
    uniform = bool(n_x < 3 or np.all(np.abs(steps - dx) <= 1e-6 * dx))
    n_xfft_df = next_pow2(n_x)
    rc = float(max_range_m) if max_range_m is not None else rmax
    n_xfft_rd = next_pow2(lam * rc / (2 * dx ** 2) + 1) if dx and math.isfinite(rc) else None
    x_fft_df = (n_xfft_df - 1) * dx if dx and n_xfft_df > 1 else None
    x_fft_rd = (n_xfft_rd - 1) * dx if dx and n_xfft_rd else None
    du_df = 1.0 / x_fft_df if x_fft_df else None
    du_rd = 1.0 / x_fft_rd if x_fft_rd else None
    return System(
        center_frequency_hz=fc, bandwidth_hz=bw, n_r=n_r, wavelength_m=lam, rail_length_m=rail_len,
        rail_step_m=dx, rail_uniform=uniform, n_x=n_x, antenna_length_azimuth_m=antenna_length_m,
        beamwidth_rad=lam / antenna_length_m, time_resolution_s=dt, range_resolution_m=dres,
        frequency_step_hz=dfreq, t_max_s=tmax, r_max_m=rmax, n_rfft=n_rfft, b_rfft_hz=b_rfft,
        range_pixel_m=pix, range_pixel_paper_m=pix_paper, image_max_range_m=rc,
        n_xfft_df=n_xfft_df, n_xfft_rd=n_xfft_rd, x_fft_df_m=x_fft_df, x_fft_rd_m=x_fft_rd,
        du_df_per_m=du_df, du_rd_per_m=du_rd,
        df_azimuth_pixel_per_rc=lam * du_df / 2 if du_df else None,
        df_azimuth_width_per_rc=lam / (2 * dx) if dx else None,
        rd_azimuth_pixel_m=dx, rd_azimuth_width_m=x_fft_rd,
        doppler_rate_coefficient=-2.0 / lam, beam_length_coefficient=lam / antenna_length_m,
        phase_coefficient_rad_per_m=-4 * math.pi / lam,
        memory_df_bytes=n_rfft * n_xfft_df * 8,
        memory_rd_bytes=n_rfft * n_xfft_rd * 8 if n_xfft_rd else None,
        raw_bytes=n_r * n_x * 8,
        df_min_range_m=df_min_range(lam, rail_len, antenna_length_m, criterion_rad),
        df_criterion_rad=criterion_rad,
    )


def system_from_scene(scene, criterion_rad: float = math.pi / 4) -> System:
    return build_system(scene.frequencies(), scene.positions_m, scene.antenna.length_azimuth_m,
                        scene.processing.get("max_range_m"), criterion_rad)


def synthetic_aperture(r0: float, xc: float, rail_length_m: float, wavelength_m: float,
                       antenna_length_m: float) -> tuple[str, float, float]:
    """Region (I-IV) and the synthetic aperture [a, b] of a point at (R0, xc) (eq. 22, 28, 34, 40).

    The beam illuminates the rail over ``|x - xc| <= lam R0/(2 L_x)``; the aperture is its
    intersection with ``[-X/2, X/2]``. Region I: beam inside the rail; II: rail inside the beam;
    III: beam cut at -X/2 only; IV: beam cut at +X/2 only.
    """
    half = wavelength_m * r0 / (2 * antenna_length_m)
    lo, hi = xc - half, xc + half
    cut_lo, cut_hi = lo < -rail_length_m / 2, hi > rail_length_m / 2
    a, b = max(lo, -rail_length_m / 2), min(hi, rail_length_m / 2)
    region = {(False, False): "I", (True, True): "II", (True, False): "III", (False, True): "IV"}[(cut_lo, cut_hi)]
    return region, a, b


def azimuth_resolution(r0: float, xc: float, rail_length_m: float, wavelength_m: float,
                       antenna_length_m: float, algorithm: str = "rd") -> tuple[str, float]:
    """Region and azimuth resolution (m) of [LeeGBSAR-II-2007]: ``lam R/(2 L_s)`` with ``L_s`` the aperture length,
    ``R = R0`` for RD/BP (eq. 27, 33, 39, 45) and ``R = Rc`` for DF (eq. 25, 31, 37, 43).

    The resolution is the paper's ``1/B`` convention: the width of the sinc response at 2/pi of
    the peak (-3.9 dB), which equals ``lam R/(2 L_s)`` exactly for a uniformly illuminated aperture.
    """
    region, a, b = synthetic_aperture(r0, xc, rail_length_m, wavelength_m, antenna_length_m)
    ls = b - a
    if ls <= 0:
        return region, math.inf
    r = math.hypot(r0, xc) if algorithm == "df" else r0
    return region, wavelength_m * r / (2 * ls)
