"""Small NISAR-layout files written with plain h5py for the tests (independent of sarcli.io.nisar).

``write_l0b``: an L0B (RRSD) with BFPQ codes (ALOS-like 5-bit LUT: code k -> k - 15.5, fill 32768 -> 0),
calibration lines, valid-sample windows, a J2-propagated orbit (ECEF, 10 s spacing) and attitude
quaternions built here with scipy's Rotation from a hand-made antenna frame (boresight perpendicular
to the ECEF velocity, ``look_deg`` off the geocentric nadir, on the right; RCS y backward).
``write_isce3_rslc``: an RSLC in the older ISCE3 variants (product group ``SLC``, complex32 image,
Doppler LUT axes one level up, epoch written with a space).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from orbit.frames import eci_to_ecef
from orbit.propagate import Keplerian, kepler_to_state, propagate_j2

C = 299_792_458.0
EPOCH_UNITS = "seconds since 2020-03-01 00:00:00"
EPOCH = "2020-03-01T00:00:00.000000Z"
T0 = 3600.0  # first pulse, s after the epoch
FILL = 32768


def orbit_ecef(t: np.ndarray):
    k = Keplerian(7_067_000.0, 0.0012, np.radians(98.0), 0.4, 1.1, 0.3)
    r0, v0 = kepler_to_state(k)
    pos, vel = propagate_j2(r0, v0, t - T0)
    return eci_to_ecef(EPOCH, t, pos, vel)


def rcs_quaternions(pos: np.ndarray, vel: np.ndarray, look_deg: float = 34.0) -> np.ndarray:
    """(n, 4) scalar-first quaternions of an RCS frame: z boresight, y = -v_hat (right-looking)."""
    vh = vel / np.linalg.norm(vel, axis=1, keepdims=True)
    down = -pos / np.linalg.norm(pos, axis=1, keepdims=True)
    down = down - np.sum(down * vh, 1, keepdims=True) * vh
    down /= np.linalg.norm(down, axis=1, keepdims=True)
    right = np.cross(down, vh)
    g = np.radians(look_deg)
    z = np.cos(g) * down + np.sin(g) * right
    y = -vh
    x = np.cross(y, z)
    q = Rotation.from_matrix(np.stack([x, y, z], axis=-1)).as_quat()  # (x, y, z, w)
    return q[:, [3, 0, 1, 2]]


def _s(v: str) -> np.bytes_:
    return np.bytes_(v)


def write_l0b(path, *, n_lines=64, n_samples=96, prf=1600.0, pols=("HH", "HV"), tx_v=False, cal_lines=(0, 40),
              window=(4, 90), fill_at=((5, 10),), seed=0, look="Right", with_attitude=True, n_sub=1,
              chirp_slope=-5e11, chirp_duration=12e-6, spacing=9.3685143125, r0=850e3) -> dict:
    """Write a synthetic L0B; returns what was written (codes, LUT, times, ...) for the checks."""
    import h5py

    rng = np.random.default_rng(seed)
    lut = np.arange(2**16, dtype=np.float32)
    lut[-(2**15):] -= 2**16
    lut -= 15.5
    lut[FILL] = 0.0
    t_tx = T0 + np.arange(n_lines) / prf
    cal = np.zeros(n_lines, np.uint8)
    for k, line in enumerate(cal_lines):
        cal[line] = 1 + (k % 2)
    out = {"lut": lut, "t_tx": t_tx, "cal": cal, "codes": {}}
    t_orb = np.arange(T0 - 120.0, T0 + 130.0, 10.0)
    pos, vel = orbit_ecef(t_orb)
    with h5py.File(path, "w") as f:
        sci = f.create_group("science/LSAR")
        ident = sci.create_group("identification")
        ident["lookDirection"] = _s(look)
        ident["orbitPassDirection"] = _s("Ascending" if vel[len(t_orb) // 2, 2] > 0 else "Descending")
        ident["missionId"] = _s("TEST")
        ident["productType"] = _s("RRSD")
        ident["listOfFrequencies"] = np.array([b"A"])
        rrsd = sci.create_group("RRSD")
        txs = [("H", t_tx)] + ([("V", t_tx + 0.5 / prf)] if tx_v else [])
        for tx, times in txs:
            g = rrsd.create_group(f"swaths/frequencyA/tx{tx}")
            d = g.create_dataset("UTCtime", data=times)
            d.attrs["units"] = EPOCH_UNITS
            g["calType"] = cal
            g["rangeLineIndex"] = np.arange(n_lines, dtype=np.int64) + 100
            g["slantRange"] = r0 + spacing * np.arange(n_samples)
            g["slantRangeSpacing"] = spacing
            g["centerFrequency"] = 1.2575e9
            g["chirpSlope"] = chirp_slope
            g["chirpDuration"] = chirp_duration
            g["rangeBandwidth"] = abs(chirp_slope) * chirp_duration
            g["nominalAcquisitionPRF"] = prf
            g["numberOfSubSwaths"] = n_sub
            g["validSamplesSubSwath1"] = np.tile(np.array(window, np.int64), (n_lines, 1))
            if n_sub > 1:
                g["validSamplesSubSwath2"] = np.tile(np.array([window[1] + 2, n_samples], np.int64), (n_lines, 1))
            for pol in pols:
                if pol[0] != tx:
                    continue
                rx = g.create_group(f"rx{pol[1]}")
                rx["BFPQLUT"] = lut
                codes = np.zeros((n_lines, n_samples), [("r", "<u2"), ("i", "<u2")])
                codes["r"] = rng.integers(0, 32, (n_lines, n_samples))
                codes["i"] = rng.integers(0, 32, (n_lines, n_samples))
                for (a, b) in fill_at:
                    codes["r"][a, b] = FILL
                ds = rx.create_dataset(pol, data=codes)
                ds.attrs["_FillValue"] = FILL
                out["codes"][pol] = codes
        tel = rrsd.create_group("lowRateTelemetry")
        o = tel.create_group("orbit")
        d = o.create_dataset("time", data=t_orb)
        d.attrs["units"] = EPOCH_UNITS
        o["position"] = pos
        o["velocity"] = vel
        if with_attitude:
            a = tel.create_group("attitude")
            ta = np.arange(T0 - 5.0, T0 + 6.0, 1.0)
            pa, va = orbit_ecef(ta)
            d = a.create_dataset("time", data=ta)
            d.attrs["units"] = "seconds since 2020-03-01T00:00:00.000000000"
            a["quaternions"] = rcs_quaternions(pa, va)
            out["attitude_time"] = ta
    return out


def write_isce3_rslc(path, image: np.ndarray, t: np.ndarray, r: np.ndarray, t_orb: np.ndarray, pos: np.ndarray,
                     vel: np.ndarray, fc: float = 1.2575e9, look: str = "Left") -> None:
    """An RSLC in older ISCE3 variants (module docstring); times in s after 2020-03-01 00:00:00."""
    import h5py

    with h5py.File(path, "w") as f:
        sci = f.create_group("science/LSAR")
        ident = sci.create_group("identification")
        ident["lookDirection"] = _s(look)
        ident["missionId"] = _s("ISCE3TEST")
        ident["productType"] = _s("SLC")
        ident["listOfFrequencies"] = np.array([b"A"])
        p = sci.create_group("SLC")
        d = p.create_dataset("swaths/zeroDopplerTime", data=t)
        d.attrs["units"] = np.bytes_(EPOCH_UNITS)
        fg = p["swaths"].create_group("frequencyA")
        c32 = np.zeros(image.shape, [("r", "<f2"), ("i", "<f2")])
        c32["r"], c32["i"] = image.real, image.imag
        fg["VV"] = c32
        fg["listOfPolarizations"] = np.array([b"VV"])
        fg["slantRange"] = r
        fg["processedCenterFrequency"] = fc
        fg["processedRangeBandwidth"] = 20e6
        fg["processedAzimuthBandwidth"] = 1000.0
        fg["nominalAcquisitionPRF"] = 1.0 / (t[1] - t[0])
        fg["sceneCenterAlongTrackSpacing"] = 4.0
        o = p.create_group("metadata/orbit")
        d = o.create_dataset("time", data=t_orb)
        d.attrs["units"] = np.bytes_("seconds since 2020-03-01T00:00:00.000000000")
        o["position"], o["velocity"] = pos, vel
        par = p.create_group("metadata/processingInformation/parameters")
        d = par.create_dataset("zeroDopplerTime", data=np.array([t[0], t[-1]]))
        d.attrs["units"] = np.bytes_(EPOCH_UNITS)
        par["slantRange"] = np.array([r[0], r[-1]])
        par["frequencyA/dopplerCentroid"] = np.array([[10.0, 20.0], [30.0, 40.0]])
