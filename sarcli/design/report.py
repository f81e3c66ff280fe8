"""Evaluate a design: every derived number with the relation that gives it, and a verdict per constraint."""

from __future__ import annotations

import math
from typing import Any

from sarcli.design import relations as rel
from sarcli.design.params import DesignParams
from sarcli.model.constants import C_LIGHT


def _constraint(name: str, ok: bool, value: float, limit: float, relation: str, note: str = "") -> dict:
    return {"name": name, "ok": bool(ok), "value": value, "limit": limit, "relation": relation, "note": note}


def _echo_window(prf: float, r_near: float, r_far: float, tau: float) -> tuple[bool, int, str]:
    """Timing-diagram check: the receive window [2 R_near/c, 2 R_far/c + tau] must lie between two
    transmit events and not overlap the transmit pulse. Returns (ok, pulses in flight, why)."""
    pri = 1.0 / prf
    t0, t1 = 2 * r_near / C_LIGHT, 2 * r_far / C_LIGHT + tau
    n0 = math.floor(t0 / pri)
    if t1 - t0 > pri - tau:
        return False, n0, "echo window plus pulse longer than the PRI"
    if math.floor(t1 / pri) != n0 or (t0 - n0 * pri) < tau:
        return False, n0, "echo window overlaps a transmit event"
    return True, n0, ""


def evaluate(p: DesignParams) -> dict[str, Any]:
    """Report as a JSON-ready dict (units in key names)."""
    if p.platform == "gbsar":
        return _evaluate_gbsar(p)
    lam = p.wavelength_m
    bw = p.bandwidth_hz if p.bandwidth_hz is not None else rel.chirp_bandwidth(p.chirp_rate_hz_per_s, p.pulse_length_s)
    notes: list[str] = []
    look = math.radians(p.look_angle_deg)
    if p.platform == "airborne":
        if p.slant_range_m:  # geometry at the given slant range (e.g. a product's range-window centre)
            slant, depression = p.slant_range_m, math.asin(min(1.0, p.altitude_m / p.slant_range_m))
        else:
            depression = look if p.look_angle_from == "horizontal" else math.pi / 2 - look
            slant = rel.flat_earth_slant_range(p.altitude_m, depression)
        incidence = math.pi / 2 - depression
    else:
        from_nadir = look if p.look_angle_from == "nadir" else math.pi / 2 - look
        if p.slant_range_m:
            from_nadir = rel.look_angle_for_slant_range(p.altitude_m, p.slant_range_m)
        slant, incidence = rel.spherical_earth_geometry(p.altitude_m, from_nadir)
    swath = p.swath_slant_m
    proc = p.processor
    if swath is None and proc.aod_aperture_m and proc.aod_velocity_mps:
        swath = rel.aod_swath(proc.aod_aperture_m, proc.aod_velocity_mps, p.pulse_length_s)
        notes.append("swath from the AOD time aperture: W = c (aperture/v_acoustic - tau) / 2")
    swath = swath or 0.0
    r_near, r_far = slant - swath / 2, slant + swath / 2
    sq = math.radians(p.squint_angle_deg)
    options = []
    for prf in p.prf_hz:
        if proc.ccd_rows and proc.ccd_line_rate_hz:
            n = rel.ccd_doppler_samples(proc.ccd_rows, proc.ccd_line_rate_hz, prf)
            t_ap = n / prf
            aperture = p.velocity_mps * t_ap
            how = "CCD: N = floor((rows-1) PRF / line_rate), L = v N / PRF"
        elif p.antenna_length_m:
            aperture = rel.beam_limited_aperture(lam, slant, p.antenna_length_m)
            t_ap = aperture / p.velocity_mps
            n = int(math.floor(t_ap * prf))
            how = "beam-limited: L = lam R / D, N = floor(L PRF / v)"
        else:
            raise ValueError("a design needs a CCD processor or an antenna length to fix the aperture")
        az = rel.azimuth_resolution(lam, slant, aperture, sq)
        ok_win, in_flight, why = _echo_window(prf, r_near, r_far, p.pulse_length_s)
        prf_max_seed = rel.prf_max_range(r_far)
        prf_min = (rel.prf_min_azimuth(p.velocity_mps, p.antenna_length_m) if p.antenna_length_m
                   else rel.processed_doppler_bandwidth(p.velocity_mps, az))
        cons = [
            _constraint("azimuth_sampling", prf > prf_min, prf, prf_min,
                        "PRF > 2v/D" if p.antenna_length_m else "PRF > v / delta_az (processed Doppler bandwidth)"),
            _constraint("range_unambiguous", prf < prf_max_seed or p.platform == "spaceborne", prf, prf_max_seed,
                        "PRF < c / (2 R_max)",
                        "" if prf < prf_max_seed else f"{in_flight} pulse(s) in flight at R_max"
                        + (" (spaceborne timing: the echo-window rule decides)" if p.platform == "spaceborne" else "")),
            _constraint("echo_window", ok_win, prf, rel.echo_window_prf_max(swath, p.pulse_length_s),
                        "receive window between transmit events", why),
        ]
        if p.antenna_length_m:
            cons.append(_constraint("azimuth_resolution_limit", az >= p.antenna_length_m / 2 - 1e-9, az,
                                    p.antenna_length_m / 2, "delta_az >= D/2 ([KimAODCCD, eq. 16])"))
        options.append({
            "prf_hz": prf, "doppler_samples": n, "aperture_time_s": t_ap, "synthetic_aperture_m": aperture,
            "azimuth_resolution_m": az, "azimuth_resolution_broadside_m": rel.azimuth_resolution(lam, slant, aperture),
            "pulses_in_flight": in_flight, "aperture_rule": how,
            "ok": all(c["ok"] for c in cons), "constraints": cons,
        })
    if p.squint_angle_deg != 90.0:
        notes.append(f"azimuth resolution uses sin({p.squint_angle_deg:g} deg) of the velocity-to-line-of-sight "
                     f"angle ([KimAODCCD, eq. 15]); a broadside side-looking radar has 90 deg: "
                     f"{options[0]['azimuth_resolution_broadside_m']:.2f} m")
    first = options[0]
    return {
        "platform": p.platform,
        "source": p.source,
        "wavelength_m": lam,
        "bandwidth_hz": bw,
        "slant_range_m": slant,
        "incidence_angle_deg": math.degrees(incidence),
        "slant_range_resolution_m": rel.slant_range_resolution(bw),
        "ground_range_resolution_m": rel.ground_range_resolution(bw, incidence),
        "azimuth_resolution_m": first["azimuth_resolution_m"],
        "swath_slant_m": swath,
        "prf_min_hz": min(c["limit"] for o in options for c in o["constraints"] if c["name"] == "azimuth_sampling"),
        "prf_max_hz": rel.prf_max_range(r_far),
        "prf_options": options,
        "ok": all(o["ok"] for o in options),
        "violations": [f"PRF {o['prf_hz']:g} Hz: {c['name']} ({c['relation']})"
                       for o in options for c in o["constraints"] if not c["ok"]],
        "notes": notes,
    }


def _evaluate_gbsar(p: DesignParams) -> dict[str, Any]:
    lam = p.wavelength_m
    bw = p.frequency_stop_hz - p.frequency_start_hz
    df = bw / (p.n_frequencies - 1)
    r_max = rel.stepped_frequency_max_range(df)
    beam = math.radians(p.beamwidth_deg)
    dx_max = rel.gbsar_max_step(lam, beam)
    # region boundary: the rail is fully inside the beam footprint beyond R_b = X / (2 tan(beam/2))
    r_boundary = p.rail_length_m / (2 * math.tan(beam / 2))
    ranges = p.ranges_m or [r_boundary / 2, r_boundary, 2 * r_boundary, r_max]
    per_range = []
    for r in ranges:
        beam_limited = r < r_boundary
        az = p.antenna_length_m / 2 if beam_limited else rel.azimuth_resolution(lam, r, p.rail_length_m)
        # incidence from the vertical: cos(i) = h / R; no ground point when R <= h
        h = p.antenna_height_m
        ground = rel.ground_range_resolution(bw, math.acos(h / r)) if r > h else None
        per_range.append({"range_m": r, "azimuth_resolution_m": az, "region": "I (beam-limited)" if beam_limited
                          else "II (rail-limited)", "ground_range_resolution_m": ground})
    cons = [_constraint("rail_sampling", p.rail_step_m <= dx_max, p.rail_step_m, dx_max, "dx <= lam / (4 sin(beam/2))")]
    return {
        "platform": "gbsar", "source": p.source, "wavelength_m": lam, "bandwidth_hz": bw,
        "frequency_step_hz": df, "r_max_m": r_max,
        "slant_range_resolution_m": rel.slant_range_resolution(bw),
        "ground_range_resolution_m": per_range[-1]["ground_range_resolution_m"],
        "azimuth_resolution_m": per_range[-1]["azimuth_resolution_m"],
        "rail_limited_beyond_m": r_boundary, "resolution_by_range": per_range,
        "prf_min_hz": None, "prf_max_hz": None, "prf_options": [],
        "ok": all(c["ok"] for c in cons), "constraints": cons,
        "violations": [c["name"] + f" ({c['relation']})" for c in cons if not c["ok"]],
        "notes": ["stop-and-go rail: no PRF; the spatial step plays its role"],
    }
