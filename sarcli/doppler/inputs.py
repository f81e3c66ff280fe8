"""Stage 0 of the Doppler pipeline: refuse a product the estimate cannot be trusted on, then undo the
receiver gain (AGC record, or gain steps recovered from the echo).

The product readers validate what they read; the estimator checks again what its answer depends on,
because a RawProduct can also come from memory (a simulator, a notebook), and because a plausible-
looking wrong number with exit 0 is the worst outcome. Each check is one ProductError line:

- at least 2 azimuth lines, one finite azimuth time per line;
- a finite, positive PRF equal to the pulse rate of the azimuth times within 1 %, and every spacing
  within 1 % of 1/PRF. Why 1 %: the CDE phase of a line pair is 2 pi fbb dt; a spacing off by eps
  pulse intervals moves that pair's phase by 2 pi fbb eps / PRF <= pi eps = 0.031 rad, i.e. 0.5 % PRF
  of centroid at |fbb| = PRF/2, the accuracy bar of the estimate, even if every pair had it. A missing
  line (a CEOS gap ingested with ``--missing keep``) is 100 %, a PRF change a few per cent, a wrong PRF
  (1e-9 Hz) or a NaN/inf time anything;
- the pulse shorter than the pulse repetition interval (PRF x pulse length < 1: a pulsed radar
  cannot transmit longer than it repeats);
- finite, positive wavelength, carrier, range sampling rate and first range, with the wavelength equal
  to c / carrier within 1e-3 (the geometry uses the wavelength, the data-only ambiguity the carrier: a
  disagreement would bias one against the other by the same fraction of the centroid).
"""

from __future__ import annotations

import dataclasses
import math
import numbers

import numpy as np

from sarcli.doppler.agcsteps import GainSteps
from sarcli.errors import ProductError
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import RawProduct

SPACING_TOLERANCE = 0.01  # of one pulse interval (module docstring)
WAVELENGTH_TOLERANCE = 1e-3


def _positive(v: object) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(v) and float(v) > 0


def check_raw(raw: RawProduct) -> None:
    """Refuse (one ProductError line) a product whose times or radar parameters make the estimate
    meaningless (module docstring)."""
    echo = raw.echo
    if echo.ndim != 2:
        raise ProductError(f"echo must be 2-D (azimuth, range), got shape {echo.shape}")
    n_lines = echo.shape[0]
    if n_lines < 2:
        raise ProductError(f"the product has {n_lines} azimuth line(s); the Doppler estimate needs at least 2")
    r = raw.radar
    for name in ("wavelength_m", "carrier_frequency_hz", "range_sampling_rate_hz", "first_range_m"):
        v = getattr(r, name)
        if not _positive(v):
            raise ProductError(f"radar {name} must be a positive number, got {v!r}")
    if abs(C_LIGHT / (r.carrier_frequency_hz * r.wavelength_m) - 1.0) > WAVELENGTH_TOLERANCE:
        raise ProductError(f"radar wavelength {r.wavelength_m} m and carrier {r.carrier_frequency_hz} Hz disagree "
                           f"(c / carrier = {C_LIGHT / r.carrier_frequency_hz} m)")
    prf = r.prf_hz
    if not _positive(prf):
        raise ProductError(f"PRF must be a positive number of Hz, got {prf!r}")
    if _positive(r.pulse_length_s) and r.pulse_length_s * prf >= 1.0:
        raise ProductError(f"PRF {prf:.6g} Hz and pulse length {r.pulse_length_s * 1e6:.6g} us: the pulse is longer "
                           f"than the pulse repetition interval ({1e6 / prf:.6g} us); one of them is wrong")
    t = np.asarray(raw.azimuth_time, np.float64)
    if t.shape != (n_lines,):
        raise ProductError(f"azimuth_time has shape {t.shape} for {n_lines} echo lines")
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise ProductError(f"azimuth_time has {bad.size} non-finite value(s) (first at line {bad[0]})")
    pulses = np.diff(t) * prf  # pulse intervals between consecutive lines, 1 for a regular train
    median = float(np.median(pulses))
    if not median > 0:
        raise ProductError("azimuth times do not increase from line to line (reversed or constant times)")
    if abs(median - 1.0) > SPACING_TOLERANCE:
        rate = prf / median
        raise ProductError(f"PRF {prf:.6g} Hz does not match the azimuth times (one line every {1.0 / rate:.6g} s, "
                           f"i.e. {rate:.6g} lines/s)")
    off = np.flatnonzero(np.abs(pulses - 1.0) > SPACING_TOLERANCE)
    if off.size:
        k = int(off[0]) + 1
        raise ProductError(f"azimuth times are not a regular pulse train: line {k} comes {pulses[k - 1]:.4g} pulse "
                           f"intervals after line {k - 1} ({off.size} irregular spacing(s): a gap, a PRF change or a "
                           f"corrupt time); the estimate needs every spacing within {SPACING_TOLERANCE:.0%} of 1/PRF "
                           "(ingest CEOS gaps with --missing zero or repeat)")


def prepare(raw: RawProduct, gain_steps: str, consume: bool = False) -> tuple[RawProduct, GainSteps | None]:
    """The product checked (:func:`check_raw`), with the per-line AGC undone and, per ``gain_steps``
    (auto: quantized products without an AGC record | on | off), the receiver-gain steps recovered
    from the echo undone; returns it with the steps found (None: not searched). The input is not
    modified (copies) unless ``consume``: then the caller gives up ``raw.echo`` and the steps are
    undone in it (no copy of the echo)."""
    check_raw(raw)
    # the AGC changes line by line as bright targets cross the beam: left in, it re-weights the azimuth
    # spectrum asymmetrically (20 Hz on samples/rs1_point.toml)
    has_agc = raw.agc_db is not None
    calibrated = raw.calibrated()
    own = calibrated.echo is not raw.echo or consume  # an echo no one else holds may be changed
    steps = None
    if gain_steps == "on" or (gain_steps == "auto" and not has_agc and raw.radar.quantization_bits > 0):
        from sarcli.doppler.agcsteps import detect_gain_steps, undo_gain_steps

        steps = detect_gain_steps(calibrated.echo)
        if steps.lines.size:
            calibrated = dataclasses.replace(calibrated, echo=undo_gain_steps(calibrated.echo, steps, in_place=own))
    return calibrated, steps
