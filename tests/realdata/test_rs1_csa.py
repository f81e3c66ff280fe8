"""Chirp scaling on the real Vancouver pass: ``csa`` against ``rd`` with the same Doppler input, and against
an independent plain-numpy implementation of the chirp-scaling equations of [CumWong2005, ch. 7] with the
published processing parameters (fdc -6900 Hz, Vr 7062 m/s, rect windows).

The coal/ferry-terminal block (1536 x 2048, bright ships and terminals) is focused with the published
Doppler as a geometric model (V = Vr, sin(theta) = -fdc lam / 2 Vr: the rate follows the range as the
book's Ka(R0) does). Statistics on the lines both focus fully: contrast std(I)/mean(I) and entropy
-sum p ln p (p = I / sum I) of the intensity, and the sub-pixel shift of the amplitude images by
cross-correlation (upsampled by a matrix DFT around the integer peak, 1/100 pixel steps).

The book's form outputs a target of closest range R0 at rho = R0 / D_ref (its bulk RCMC keeps the
reference frequency's migration, module docstring of sarcli.focus.csa) and its azimuth FFT is circular
over the block (the target at its zero-Doppler time modulo the block): sarcli's column i (R0_i) is the
book's column (R0_i / D_ref - r_first) / dr, 82.2 columns further at mid-swath, and its line j the book's
line j - shift (modulo the block). Both are compared in a 256 x 256 window, across which the range
stretch 1 / D_ref moves the offset by 0.05 column.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from sarcli.focus.csa import focus_csa
from sarcli.focus.rda import focus_rd
from sarcli.model.doppler import GeometricDoppler

C = 299792458.0
FDC, VR = -6900.0, 7062.0


def book_csa(echo, radar, fdc, vr, band):
    """Chirp scaling as printed in [CumWong2005, ch. 7] (eqs. 7.30-7.34), plain numpy, complex128, rect
    windows: azimuth FFT; chirp scaling exp(j pi Km (D_ref / D - 1) tau'^2), tau' = tau - 2 R_ref / (c D);
    range FFT; range compression exp(j pi D f^2 / (Km D_ref)) and bulk RCMC exp(j 4 pi f R_ref (1 / D -
    1 / D_ref) / c); range IFFT; azimuth filter exp(j 4 pi R0 f0 D / c) and residual phase
    exp(-j 4 pi Km (1 - D / D_ref) (R0 - R_ref)^2 / (c^2 D^2)), R0 = D_ref c tau / 2; azimuth IFFT.
    R_ref: mid-swath; the range axis zero-padded by one pulse (the chirps of far targets); the azimuth
    band ``band`` (Hz) around fdc kept (rect), as sarcli's processed band, and the range frequencies of the
    scaled chirp band |K| T D_ref / D (beyond it only receiver noise: 7 % of the power at 32.3 MHz
    sampling of a 30.1 MHz chirp)."""
    f0, fs, kr, prf = radar.carrier_frequency_hz, radar.range_sampling_rate_hz, radar.chirp_rate_hz_per_s, radar.prf_hz
    na, nr = echo.shape
    npad = int(round(radar.pulse_length_s * fs))
    tau = 2 * radar.first_range_m / C + np.arange(nr + npad) / fs
    s = np.zeros((na, nr + npad), complex)
    s[:, :nr] = echo
    s = np.fft.fft(s, axis=0)
    f = np.fft.fftfreq(na, 1 / prf)
    f = fdc + np.mod(f - fdc + prf / 2, prf) - prf / 2
    d = np.sqrt(1 - (C * f / (2 * vr * f0)) ** 2)[:, None]
    d_ref = np.sqrt(1 - (C * fdc / (2 * vr * f0)) ** 2)
    r_ref = C * tau[nr // 2] / 2
    km = kr / (1 - kr * C * r_ref * f[:, None] ** 2 / (2 * vr**2 * f0**3 * d**3))
    s *= np.exp(1j * np.pi * km * (d_ref / d - 1) * (tau[None, :] - 2 * r_ref / (C * d)) ** 2)
    s = np.fft.fft(s, axis=1)
    ft = np.fft.fftfreq(nr + npad, 1 / fs)[None, :]
    s *= np.exp(1j * np.pi * d * ft**2 / (km * d_ref)) * np.exp(4j * np.pi * ft * r_ref * (1 / d - 1 / d_ref) / C)
    s *= np.abs(ft) <= 0.5 * abs(kr) * radar.pulse_length_s * d_ref / d  # the scaled chirp band
    s = np.fft.ifft(s, axis=1)[:, :nr]
    r0 = d_ref * C * tau[None, :nr] / 2
    s *= np.exp(4j * np.pi * r0 * f0 * d / C) * np.exp(-4j * np.pi * km * (1 - d / d_ref) * (r0 - r_ref) ** 2
                                                      / (C**2 * d**2))
    s *= (np.abs(f - fdc) <= 0.5 * band)[:, None]
    return np.fft.ifft(s, axis=0), d_ref


def shift_between(a, b, up=100):
    """(rows, cols) by which amplitude image ``b`` must move to match ``a`` (cross-correlation of the
    mean-removed amplitudes; the integer peak refined on a 1/up grid by a matrix DFT over +-1.5 pixel)."""
    fa = np.fft.fft2(np.abs(a) - np.abs(a).mean())
    fb = np.fft.fft2(np.abs(b) - np.abs(b).mean())
    x = fa * np.conj(fb)
    cc = np.abs(np.fft.ifft2(x))
    i, j = np.unravel_index(int(np.argmax(cc)), cc.shape)
    n, m = cc.shape
    i0 = i - n if i > n // 2 else i
    j0 = j - m if j > m // 2 else j
    dr = i0 + np.arange(-150, 151) / up
    dc = j0 + np.arange(-150, 151) / up
    er = np.exp(2j * np.pi * np.outer(dr, np.fft.fftfreq(n)))
    ec = np.exp(2j * np.pi * np.outer(np.fft.fftfreq(m), dc))
    z = np.abs(er @ x @ ec)
    k, q = np.unravel_index(int(np.argmax(z)), z.shape)
    return float(dr[k]), float(dc[q])


def stats(img):
    i = np.abs(img.astype(np.complex128)) ** 2
    p = i / i.sum()
    return i.std() / i.mean(), float(-np.sum(p[p > 0] * np.log(p[p > 0])))


def _published(raw):
    lam = raw.radar.wavelength_m
    return GeometricDoppler(VR, -FDC * lam / (2 * VR), lam)


@pytest.fixture(scope="module")
def focused(rs1_raws):
    raw = rs1_raws["coal_ferry_terminals"]
    dop = _published(raw)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = {"raw": raw, "rd": focus_rd(raw, dop), "csa": focus_csa(raw, dop),
               "csa_rect": focus_csa(raw, dop, range_window="rect", azimuth_window="rect")}
    band = out["csa_rect"].parameters["azimuth_bandwidth_hz"]
    out["book"] = book_csa(raw.echo.astype(np.complex128), raw.radar, FDC, VR, band)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", ["coal_ferry_terminals", "block1"])
def test_csa_and_rd_agree_on_a_real_block(focused, rs1_raws, name):
    """Same Doppler, default windows: contrast and entropy within 2 % (the issue's "a few per cent";
    measured: contrast 22.56 / 22.56 and 45.09 / 45.27, entropy within 0.06 %), the images register
    within 0.1 pixel (measured 0.00 in a 256 x 256 window at mid-scene), and the amplitudes of the fully
    focused lines correlate above 0.99 (measured 0.9996 on both blocks)."""
    if name == "coal_ferry_terminals":
        rd, csa = focused["rd"], focused["csa"]
    else:
        raw = rs1_raws[name]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rd, csa = focus_rd(raw, _published(raw)), focus_csa(raw, _published(raw))
    lo, hi = max(rd.first_full_line, csa.first_full_line), min(rd.last_full_line, csa.last_full_line) + 1
    a, b = rd.image[lo:hi], csa.image[lo:hi]
    (c_rd, e_rd), (c_csa, e_csa) = stats(a), stats(b)
    assert abs(c_csa / c_rd - 1) < 0.02 and abs(e_csa / e_rd - 1) < 0.02, (c_rd, c_csa, e_rd, e_csa)
    mid_r, mid_c = (lo + hi) // 2, a.shape[1] // 2
    wa = rd.image[mid_r - 128:mid_r + 128, mid_c - 128:mid_c + 128]
    wb = csa.image[mid_r - 128:mid_r + 128, mid_c - 128:mid_c + 128]
    dr, dc = shift_between(wa, wb)
    assert abs(dr) < 0.1 and abs(dc) < 0.1, (dr, dc)
    assert np.corrcoef(np.abs(a).ravel(), np.abs(b).ravel())[0, 1] > 0.99


@pytest.mark.slow
def test_csa_reproduces_the_book_chirp_scaling(focused):
    """The book's equations (independent numpy, published parameters, rect windows, the same azimuth band)
    against csa with the same windows, in 256 x 256 windows at near, mid and far range. What agrees
    (measured): the offset is the R0 / D_ref mapping to 0.04, 0.17, 0.05 column and 0.01 line (csa and
    rd register to 0.00 in the same windows; the book function's mapping is exact to 0.002 column on a
    point target: the book's image sits there), the amplitudes correlate at 0.980, 0.885, 0.992 (csa vs
    rd: 0.981, 0.972, 0.998), the entropy of the fully focused lines agrees to 1.3 %; the book's contrast
    is 7.6 % lower (19.5 vs 21.1; rd 21.0). Bars: 0.2 column, 0.05 line, correlation 0.85, entropy 2 %,
    contrast 10 %: the agreement is that of two chirp-scaling images of the same echo, not bit-level
    (the book's normalization, Km reference range and amplitude per row differ)."""
    csa, raw = focused["csa_rect"], focused["raw"]
    book, d_ref = focused["book"]
    book = np.roll(book, csa.parameters["shift_lines"], axis=0)
    dr = csa.range_spacing_m
    lo, hi = csa.first_full_line, csa.last_full_line + 1
    mid_r = (lo + hi) // 2
    for mid_c in (400, 1024, 1600):
        expect = (csa.slant_range[mid_c] / d_ref - raw.radar.first_range_m) / dr - mid_c  # book col - csa col
        k = int(round(expect))
        a = csa.image[mid_r - 128:mid_r + 128, mid_c - 128:mid_c + 128]
        b = book[mid_r - 128:mid_r + 128, mid_c + k - 128:mid_c + k + 128]
        srow, scol = shift_between(a, b)
        assert abs(srow) < 0.05 and abs(scol - (k - expect)) < 0.2, (mid_c, srow, scol, k - expect)
        fr = np.fft.fftfreq(b.shape[1])
        bs = np.fft.ifft(np.fft.fft(b, axis=1) * np.exp(-2j * np.pi * fr * scol), axis=1)
        rho = np.corrcoef(np.abs(a[:, 4:-4]).ravel(), np.abs(bs[:, 4:-4]).ravel())[0, 1]
        assert rho > 0.85, (mid_c, rho)
    nr = csa.image.shape[1]
    k = int(round((csa.slant_range[nr // 2] / d_ref - raw.radar.first_range_m) / dr - nr // 2))
    (c_a, e_a) = stats(csa.image[lo:hi, 0:nr - 100])
    (c_b, e_b) = stats(book[lo:hi, k:nr - 100 + k])
    assert abs(c_a / c_b - 1) < 0.1 and abs(e_a / e_b - 1) < 0.02, (c_a, c_b, e_a, e_b)
