"""The ``sicd`` export format: an SLC as NGA SICD 1.4.0 in NITF, written and checked by sarkit.

Geometry (SICD Vol. 1 and 3, [NGA-SICD]): a sarcli SLC is a zero-Doppler range-Doppler image,
SICD's range-migration ``RMA`` formation with the ``INCA`` image type on a ``RGZERO`` slant-plane grid.
SICD rows are ranges and columns azimuth lines, so the pixel array is the SLC transposed (a left-looking
SLC also has its lines reversed: SICD's column axis must make the grid normal point away from the Earth).

- SCP: the centre pixel (zero-Doppler time t_s, range R_s), geolocated on the ellipsoid raised by the
  focusing height (``orbit.geometry.geolocate``); times are s after ``CollectStart``.
- ARP: a degree-5 polynomial fitted to the ECEF orbit (Hermite-interpolated) over the collect.
- Row (range): u_row = unit(SCP - ARP(t_s)), SS = the range pixel spacing, KCtr = 2 f_c / c, ImpRespBW =
  2 B_r / c (processed range band), the spectrum centred (DeltaKCOAPoly 0).
- INCA: R_CA_SCP = R_s; the Doppler rate model f_r(R) = -2 |V|^2 DRSF(R) / (lam R) (a straight track has
  DRSF = 1; an orbit's effective velocity makes it < 1) gives DRateSFPoly(xrow) = -f_r(R_s + xrow) lam
  (R_s + xrow) / (2 |V(t_s)|^2), f_r from the SLC's Doppler record (the block nearest t_s);
  Col.SS = |V| dt DRSF(0) (the along-track ground spacing of lines dt apart) and TimeCAPoly(ycol) =
  t_s + ycol dt / Col.SS; DopCentroidPoly(xrow) = f_dc(R_s + xrow), DopCentroidCOA true.
- Col (azimuth): u_col = s unit(V - (V.u_row) u_row) (s = +1 right-looking, -1 left), KCtr 0, ImpRespBW =
  B_a / (PRF Col.SS) (the processed Doppler band in cycles per metre: PRF <-> 1/Col.SS), the spectrum
  centred on DeltaKCOAPoly(xrow) = s W(f_dc) / (PRF Col.SS) (W wraps into the PRF band; Sgn = -1: the
  image-to-frequency transform has exponent -1, so a line phase ramp exp(+j 2 pi f t) sits at +f).
- Grid.TimeCOAPoly: the zero-Doppler time t_ca (DopCentroidCOA false). SICD projects a pixel with the INCA
  range model R(t)^2 = R_CA^2 + DRSF |V|^2 (t - t_ca)^2 evaluated at the COA; at t_ca it is exact
  (R = R_CA, dR/dt = 0), while at the beam centre t_ca + f_dc / f_r it is a hyperbola far from its vertex
  when the squint is large: RADARSAT-1's beam centre is 3.7 s (26 km of track) after zero Doppler, and a
  beam-centre COA put the projected pixels 26 m (5 lines) away from sarcli's zero-Doppler geolocation;
  with the zero-Doppler COA they agree to micrometres. The Doppler centroid stays in DopCentroidPoly and
  in the column spectrum (DeltaKCOAPoly).
- IRW: the -3 dB width of the transform of the processing window (sarcli's ``range_window`` /
  ``azimuth_window``) over the processed band, divided by ImpRespBW.
- SCPCOA: sarkit's own computation from the above (``compute_scp_coa``), so it is consistent by construction.
- Radiometric (written whenever the SLC carries ``/calibration``; SICD Vol. 1, [NGA-SICD]): SICD's scale
  factors multiply pixel power as NISAR's look-up tables do (beta0 = |DN|^2 L_beta0,
  :mod:`sarcli.calibration.radiometry`), so BetaZeroSFPoly, SigmaZeroSFPoly and GammaZeroSFPoly (ellipsoid
  incidence) are 2-D polynomials in (xrow, ycol) fitted to L_beta0, L_sigma0, L_gamma0 on a 48 x 48 grid of
  the image's pixels (least squares in relative error, the lowest degree of (2, 1) ... (6, 3) within
  0.01 dB, else (6, 3); over the calibrated pixels: outside the product's calibrated area the
  polynomial is an extrapolation). RCSSFPoly = BetaZeroSFPoly / (Row.ImpRespBW Col.ImpRespBW), the
  divisor SICD's slant-plane area of a pixel without a WgtFunct: RCS = RCSSF x the integrated pixel power. NoiseLevel
  (ABSOLUTE): NoisePoly the noise power of a pixel in dB, 10 log10(NESZ / L_sigma0), fitted in dB, when
  the product has a noise floor. The largest misfit on the grid is reported (``radiometric_fit_db``).

The writer refuses (one line) an SLC without an Earth orbit (none, or LOCAL) or without its processed
bandwidths. ``sarkit`` is an optional dependency (``pip install 'sarcli[sicd]'``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sarcli.errors import ConfigError, ProductError
from sarcli.model.constants import C_LIGHT
from sarcli.model.slc import SLC

NS = "urn:SICD:1.4.0"
ARP_DEGREE = 5


@dataclass(frozen=True)
class SicdOptions:
    """polarization: transmit-receive polarization of the image (a sarcli SLC does not record it: ``HH``,
    ``VV``, ``HV``, ``VH`` or SICD's ``H:H`` ...); collector: CollectionInfo/CollectorName (default: the SLC's sensor);
    classification: the security classification marking (NITF and SICD)."""

    polarization: str = "H:H"
    collector: str | None = None
    classification: str = "UNCLASSIFIED"


def sarkit_sicd():
    """``sarkit.sicd``, or a one-line refusal when the optional dependency is missing."""
    try:
        import sarkit.sicd
    except ImportError:
        raise ConfigError("--format sicd needs sarkit: pip install 'sarcli[sicd]'") from None
    return sarkit.sicd


def irw_factor(spec: str | None, n: int = 2048, pad: int = 64) -> float:
    """-3 dB width of the impulse response of the window ``spec`` over a unit band (1 / band units):
    0.886 for rect, 1.30 x that for hamming (0.54)."""
    from sarcli.focus.windows import window

    u = (np.arange(n) - n / 2) / n
    w = window(spec or "rect", u)
    p = np.abs(np.fft.fftshift(np.fft.fft(w, n * pad))) ** 2
    p /= p.max()
    k = int(np.argmax(p))
    above = np.flatnonzero(p[k:] < 0.5)[0]
    # linear interpolation of the half-power crossing, both sides (symmetric window)
    x = above - 1 + (p[k + above - 1] - 0.5) / (p[k + above - 1] - p[k + above])
    return float(2 * x / pad)


def _poly1(x: np.ndarray, y: np.ndarray, deg: int) -> np.ndarray:
    """Least-squares polynomial coefficients (lowest order first) of y(x), x scaled for conditioning."""
    s = max(float(np.max(np.abs(x))), 1e-12)
    c = np.polynomial.polynomial.polyfit(x / s, y, deg)
    return c / s ** np.arange(deg + 1)


def _poly2(x: np.ndarray, y: np.ndarray, z: np.ndarray, dx: int, dy: int) -> np.ndarray:
    """Least-squares 2-D polynomial coefficients c[i, j] of z(x, y) = sum c[i, j] x^i y^j."""
    sx, sy = max(float(np.max(np.abs(x))), 1e-12), max(float(np.max(np.abs(y))), 1e-12)
    a = np.stack([(x / sx) ** i * (y / sy) ** j for i in range(dx + 1) for j in range(dy + 1)], axis=-1)
    c, *_ = np.linalg.lstsq(a, z, rcond=None)
    c = c.reshape(dx + 1, dy + 1)
    return c / (sx ** np.arange(dx + 1))[:, None] / (sy ** np.arange(dy + 1))[None, :]


def _wrap(f: np.ndarray, prf: float) -> np.ndarray:
    return f - prf * np.round(f / prf)


class SicdFormat:
    """SICD 1.4.0 in NITF through sarkit (module docstring)."""

    name = "sicd"
    description = "NGA SICD 1.4.0 (NITF) through sarkit: opens in every SICD tool"
    suffix = ".nitf"
    Options = SicdOptions

    def xml(self, slc: SLC, options: SicdOptions):
        """The SICD XML tree (lxml), the pixel array (complex64, SICD rows = ranges) of ``slc`` and the
        largest misfits (dB) of its radiometric polynomials (empty without calibration)."""
        import lxml.etree

        sksicd = sarkit_sicd()

        from orbit.errors import OrbitError
        from orbit.geodetic import ecef_to_geodetic
        from orbit.geometry import geolocate
        from orbit.statevectors import StateVectors
        from sarcli import __version__
        from sarcli.io.h5common import created_utc, parse_utc
        from sarcli.io.images import SENSORS, utc_after
        from sarcli.io.slc import recorded_height
        from sarcli.workflows.export import processed_bands

        if slc.orbit is None or slc.orbit.frame == "LOCAL":
            raise ProductError("a SICD needs an Earth orbit (ECI or ECEF state vectors); this SLC has "
                               f"{'none' if slc.orbit is None else 'a LOCAL (flat-Earth) orbit'}")
        n_az, n_r = slc.image.shape
        if n_az < 2 or n_r < 2:
            raise ProductError(f"image {slc.image.shape} is too small for a SICD grid")
        _, b_r, b_a = processed_bands(slc, "a SICD")
        side = 1.0 if slc.look_side == "right" else -1.0
        t_az = np.asarray(slc.azimuth_time, np.float64)
        rng = np.asarray(slc.slant_range, np.float64)
        dt = float(np.median(np.diff(t_az)))
        ss_r = float(np.median(np.diff(rng)))
        prf = 1.0 / dt
        lam = slc.radar.wavelength_m
        fc = C_LIGHT / lam
        h = recorded_height(slc.parameters)
        try:
            sv = StateVectors.from_record(slc.orbit, slc.epoch_utc).to_ecef()
        except OrbitError as e:
            raise ProductError(f"SLC orbit: {e}") from None
        i_s, j_s = n_az // 2, n_r // 2
        t_s, r_s = float(t_az[i_s]), float(rng[j_s])
        scp = geolocate(sv, t_s, r_s, lam, 0.0, h, slc.look_side)
        p_s, v_s, _ = sv.interpolate(t_s)
        speed = float(np.linalg.norm(v_s))
        # the Doppler record of the block nearest the SCP time, on the image's ranges
        d = slc.doppler
        k = int(np.argmin(np.abs(np.asarray(d.block_time) - t_s)))
        fdc = np.interp(rng, d.range_m, np.asarray(d.fdc_hz)[k])
        fr = np.interp(rng, d.range_m, np.asarray(d.fr_hz_per_s)[k])
        xrow = rng - r_s
        drsf = -fr * lam * rng / (2 * speed ** 2)
        drsf_poly = _poly1(xrow, drsf, 2)
        col_ss = speed * dt * float(drsf_poly[0])
        if not col_ss > 0:
            raise ProductError(f"the SLC's Doppler rate at the scene centre ({fr[j_s]:.4g} Hz/s) has the wrong sign "
                               "for a side-looking image")
        # time axis: seconds after CollectStart, which holds the whole aperture of every line
        t_coa_line = t_az[:, None] + (fdc / fr)[None, :]
        half_ap = 0.5 * b_a / np.max(np.abs(fr))
        t0 = float(min(t_az.min(), t_coa_line.min()) - half_ap)
        t1 = float(max(t_az.max(), t_coa_line.max()) + half_ap)
        dur = t1 - t0
        order = slice(None) if side > 0 else slice(None, None, -1)
        pixels = np.ascontiguousarray(np.asarray(slc.image, np.complex64)[order].T)
        lines = t_az[order]
        ycol = (lines - t_s) / dt * col_ss * side
        # polynomials in (xrow, ycol)
        xx, yy = np.meshgrid(xrow[:: max(1, n_r // 16)], ycol[:: max(1, n_az // 16)], indexing="ij")
        t_coa = (t_s + yy * dt / col_ss * side) - t0  # the zero-Doppler time (module docstring)
        tcoa_poly = _poly2(xx.ravel(), yy.ravel(), t_coa.ravel(), 0, 1)
        tt = np.linspace(t0 - 1.0, t1 + 1.0, 64)
        try:
            pos, _, _ = sv.interpolate(tt)
        except OrbitError as e:
            raise ProductError(f"the orbit does not cover the collect {t0:.3f}..{t1:.3f} s: {e}") from None
        arp_poly = np.stack([_poly1(tt - t0, pos[:, i], ARP_DEGREE) for i in range(3)], axis=-1)
        u_row = (scp - p_s) / np.linalg.norm(scp - p_s)
        v_perp = v_s - np.dot(v_s, u_row) * u_row
        u_col = side * v_perp / np.linalg.norm(v_perp)
        p = slc.parameters or {}
        row_bw, col_bw = 2 * b_r / C_LIGHT, b_a / (prf * col_ss)
        dk_col = _poly1(xrow, side * _wrap(fdc, prf) / (prf * col_ss), 2)
        dk_lo, dk_hi = float(np.min(np.polynomial.polynomial.polyval(xrow, dk_col))), \
            float(np.max(np.polynomial.polynomial.polyval(xrow, dk_col)))
        col_k1, col_k2 = dk_lo - col_bw / 2, dk_hi + col_bw / 2
        if col_k1 < -0.5 / col_ss or col_k2 > 0.5 / col_ss:  # the band wraps: SICD then spans the whole band
            col_k1, col_k2 = -0.5 / col_ss, 0.5 / col_ss
        lat, lon, hae = (float(np.ravel(x)[0]) for x in ecef_to_geodetic(scp[None, :]))
        # ICPs 1:FRFC, 2:FRLC, 3:LRLC, 4:LRFC (rows are ranges, columns lines in SICD order)
        corners_t = lines[[0, -1, -1, 0]]
        corners_r = rng[[0, 0, -1, -1]]
        cpos = geolocate(sv, corners_t, corners_r, lam, 0.0, np.full(4, h), slc.look_side)
        clat, clon, _ = ecef_to_geodetic(cpos)
        pol = options.polarization.upper()
        pol = f"{pol[0]}:{pol[1]}" if len(pol) == 2 else pol  # HH (NISAR's spelling) -> H:H
        if pol not in ("H:H", "H:V", "V:H", "V:V"):
            raise ConfigError(f"SICD polarization {options.polarization!r}: use HH, HV, VH or VV (or H:H ...)")

        root = sksicd.ElementWrapper(lxml.etree.Element(f"{{{NS}}}SICD"))
        ci = root["CollectionInfo"]
        ci["CollectorName"] = options.collector or SENSORS.get(slc.source, slc.source)
        ci["CoreName"] = Path(str(p.get("raw", "sarcli"))).stem or "sarcli"
        ci["CollectType"] = "MONOSTATIC"
        ci["RadarMode"] = {"ModeType": "STRIPMAP"}
        ci["Classification"] = options.classification
        root["ImageCreation"] = {"Application": f"sarcli {__version__}",
                                 "DateTime": parse_utc(created_utc()),
                                 "Profile": "sarcli export --format sicd"}
        root["ImageData"] = {"PixelType": "RE32F_IM32F", "NumRows": n_r, "NumCols": n_az, "FirstRow": 0,
                             "FirstCol": 0, "FullImage": {"NumRows": n_r, "NumCols": n_az},
                             "SCPPixel": np.array([j_s, n_az - 1 - i_s if side < 0 else i_s])}
        root["GeoData"] = {"EarthModel": "WGS_84", "SCP": {"ECF": scp, "LLH": np.array([lat, lon, hae])},
                           "ImageCorners": np.column_stack([clat, clon])}
        root["Grid"] = {
            "ImagePlane": "SLANT", "Type": "RGZERO", "TimeCOAPoly": tcoa_poly,
            "Row": {"UVectECF": u_row, "SS": ss_r, "ImpRespWid": irw_factor(p.get("range_window")) / row_bw,
                    "Sgn": -1, "ImpRespBW": row_bw, "KCtr": 2 * fc / C_LIGHT, "DeltaK1": -row_bw / 2,
                    "DeltaK2": row_bw / 2, "DeltaKCOAPoly": np.zeros((1, 1))},
            "Col": {"UVectECF": u_col, "SS": col_ss, "ImpRespWid": irw_factor(p.get("azimuth_window")) / col_bw,
                    "Sgn": -1, "ImpRespBW": col_bw, "KCtr": 0.0, "DeltaK1": col_k1, "DeltaK2": col_k2,
                    "DeltaKCOAPoly": dk_col[:, None]},
        }
        start = utc_after(slc.epoch_utc, t0)
        root["Timeline"] = {"CollectStart": parse_utc(start), "CollectDuration": dur}
        root["Timeline"]["IPP"] = {"@size": 1}
        ipp = root["Timeline"]["IPP"]
        ipp["Set"] = ({"@index": 1, "TStart": 0.0, "TEnd": dur, "IPPStart": 0, "IPPEnd": int(round(dur * prf)) - 1,
                       "IPPPoly": np.array([0.0, prf])},)
        root["Position"] = {"ARPPoly": arp_poly}
        root["RadarCollection"] = {
            "TxFrequency": {"Min": fc - b_r / 2, "Max": fc + b_r / 2}, "TxPolarization": pol[0],
            "RcvChannels": {"@size": 1}}
        root["RadarCollection"]["RcvChannels"]["ChanParameters"] = ({"@index": 1, "TxRcvPolarization": pol},)
        root["ImageFormation"] = {
            "RcvChanProc": {"NumChanProc": 1, "ChanIndex": (1,)}, "TxRcvPolarizationProc": pol,
            "TStartProc": 0.0, "TEndProc": dur, "TxFrequencyProc": {"MinProc": fc - b_r / 2, "MaxProc": fc + b_r / 2},
            "ImageFormAlgo": "RMA", "STBeamComp": "NO", "ImageBeamComp": "NO", "AzAutofocus": "NO",
            "RgAutofocus": "NO"}
        root["RMA"] = {"RMAlgoType": "RG_DOP", "ImageType": "INCA", "INCA": {
            "TimeCAPoly": np.array([t_s - t0, side * dt / col_ss]), "R_CA_SCP": r_s, "FreqZero": fc,
            "DRateSFPoly": drsf_poly[:, None], "DopCentroidPoly": _poly1(xrow, fdc, 2)[:, None],
            "DopCentroidCOA": False}}
        tree = root.elem.getroottree()
        scpcoa = sksicd.compute_scp_coa(tree)
        root.elem.insert(list(root.elem).index(root["ImageFormation"].elem) + 1, scpcoa)
        fit_db: dict[str, float] = {}
        if slc.calibration is not None:
            radiometric, fit_db = radiometric_polys(slc, r_s, t_s, dt, col_ss * side, row_bw * col_bw)
            if radiometric:
                root["Radiometric"] = radiometric
                elem = root["Radiometric"].elem
                root.elem.remove(elem)  # SICD's order: SCPCOA, then Radiometric
                root.elem.insert(list(root.elem).index(scpcoa) + 1, elem)
        return tree, pixels, fit_db

    def write(self, slc: SLC, output: Path, options: SicdOptions, inputs: tuple[Path, ...]) -> dict[str, Any]:
        from sarcli.io.atomic import atomic_path

        sksicd = sarkit_sicd()

        tree, pixels, fit_db = self.xml(slc, options)
        clas = options.classification[0].upper()
        sec = {"security": {"clas": clas}}
        meta = sksicd.NitfMetadata(
            xmltree=tree, file_header_part={"ostaid": "sarcli", "ftitle": Path(output).stem[:80]} | sec,
            im_subheader_part={"isorce": str(tree.findtext("{*}CollectionInfo/{*}CollectorName"))[:42]} | sec,
            de_subheader_part=sec)
        with atomic_path(output, ".nitf") as tmp, open(tmp, "wb") as f, sksicd.NitfWriter(f, meta) as w:
            w.write_image(pixels)
        return {"rows": int(pixels.shape[0]), "cols": int(pixels.shape[1]),
                "scp_lat_lon_hae": [float(tree.findtext(f"{{*}}GeoData/{{*}}SCP/{{*}}LLH/{{*}}{k}"))
                                    for k in ("Lat", "Lon", "HAE")],
                "col_ss_m": float(tree.findtext("{*}Grid/{*}Col/{*}SS")),
                **({"radiometric_fit_db": fit_db} if fit_db else {})}


FIT_DEGREES = ((2, 1), (3, 1), (4, 2), (5, 2), (6, 3))
FIT_TOLERANCE_DB = 0.01


def _sf_fit(xx: np.ndarray, yy: np.ndarray, lut: np.ndarray) -> tuple[np.ndarray, float]:
    """A scale-factor polynomial c[i, j] (x^i y^j) fitted to the positive values ``lut`` (least squares in
    relative error) and its largest misfit in dB: the lowest degree of FIT_DEGREES within
    FIT_TOLERANCE_DB, else the highest."""
    sx, sy = max(float(np.max(np.abs(xx))), 1e-12), max(float(np.max(np.abs(yy))), 1e-12)
    best: tuple[np.ndarray, float] = (np.zeros((1, 1)), math.inf)
    for dx, dy in FIT_DEGREES:
        a = np.stack([(xx / sx) ** i * (yy / sy) ** j for i in range(dx + 1) for j in range(dy + 1)], axis=-1)
        c, *_ = np.linalg.lstsq(a / lut[:, None], np.ones_like(lut), rcond=None)
        fit = a @ c
        err = float(np.max(np.abs(10 * np.log10(np.maximum(fit, 1e-300) / lut))))
        best = (c.reshape(dx + 1, dy + 1) / (sx ** np.arange(dx + 1))[:, None] / (sy ** np.arange(dy + 1))[None, :],
                err)
        if err <= FIT_TOLERANCE_DB:
            break
    return best


def radiometric_polys(slc: SLC, r_s: float, t_s: float, dt: float, col_per_line: float,
                      bw_area: float) -> tuple[dict[str, Any], dict[str, float]]:
    """SICD's Radiometric block of ``slc``'s look-up tables (module docstring) and the fits' largest
    misfits (dB); empty when no pixel is calibrated. ``col_per_line``: ycol (m) per line after t_s
    (signed); ``bw_area``: Row.ImpRespBW x Col.ImpRespBW (1/m^2)."""
    from sarcli.calibration.radiometry import lut_on

    cal = slc.calibration
    if cal is None:
        return {}, {}
    n_az, n_r = slc.image.shape
    i = np.unique(np.linspace(0, n_az - 1, 48).round().astype(int))
    j = np.unique(np.linspace(0, n_r - 1, 48).round().astype(int))
    t, r = np.asarray(slc.azimuth_time, np.float64)[i], np.asarray(slc.slant_range, np.float64)[j]
    xx, yy = np.meshgrid(r - r_s, (t - t_s) / dt * col_per_line, indexing="ij")  # (range, line) as SICD
    luts = {k: lut_on(cal, k, t, r).T for k in ("beta0", "sigma0", "gamma0", "nes0")}
    ok = np.isfinite(luts["beta0"]) & (luts["beta0"] > 0)
    if not ok.any():
        return {}, {}
    out: dict[str, np.ndarray] = {}
    err: dict[str, float] = {}
    for k in ("beta0", "sigma0", "gamma0"):
        good = ok & np.isfinite(luts[k]) & (luts[k] > 0)
        c, err[k] = _sf_fit(xx[good], yy[good], luts[k][good])
        out[{"beta0": "BetaZero", "sigma0": "SigmaZero", "gamma0": "GammaZero"}[k] + "SFPoly"] = c
    radiometric: dict[str, Any] = {  # SICD's order
        "RCSSFPoly": out["BetaZeroSFPoly"] / bw_area, "SigmaZeroSFPoly": out["SigmaZeroSFPoly"],
        "BetaZeroSFPoly": out["BetaZeroSFPoly"], "GammaZeroSFPoly": out["GammaZeroSFPoly"]}
    noise = luts["nes0"] / luts["sigma0"]
    good = ok & np.isfinite(noise) & (noise > 0)
    if good.any():
        db = 10 * np.log10(noise[good])
        for dx, dy in FIT_DEGREES:
            c = _poly2(xx[good], yy[good], db, dx, dy)
            err["noise"] = float(np.max(np.abs(np.polynomial.polynomial.polyval2d(xx[good], yy[good], c) - db)))
            if err["noise"] <= FIT_TOLERANCE_DB:
                break
        radiometric = {"NoiseLevel": {"NoiseLevelType": "ABSOLUTE", "NoisePoly": c}, **radiometric}
    return radiometric, err


SICD = SicdFormat()
