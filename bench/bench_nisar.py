"""NISAR in and out on real and simulated data: the figures quoted in docs/nisar.md.

1. The real ALOS-1 PALSAR L0B cut (../shared/data/alos_palsar_l0b, 1000 x 2200): read time; Doppler
   centroid from the data (CDE, 250 x 128 blocks) with its standard error against the centroid
   predicted from orbit + attitude quaternions, the attitude error their difference amounts to
   (sensitivity of the predicted centroid to 0.01 deg of pitch and of yaw), the data-only ambiguity
   (MLCC, MLBF); focusing: the synthetic aperture against the 1000 lines at the default band (0.8 PRF)
   and the fully focused span at a reduced band; quicklooks docs/images/nisar_alos_rc.png (range
   compressed) and docs/images/nisar_alos_focused.png; RSLC export of the focused image.
2. The simulated point targets of tests/nisar/scenes/cr_points.toml written as an RSLC and analysed
   with a CSV of their positions: offsets (pixels) and IRWs against theory; the IRF picture
   docs/images/nisar_cr_sim.png.
3. Optionally an RSLC and its corner-reflector CSV given by SARCLI_RSLC and SARCLI_RSLC_CSV (e.g. the
   ISCE3 ALOS test products): the per-reflector records.

Section 1 is skipped (and says so) when ../shared/data is absent.
"""

from __future__ import annotations

import os
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from bench.common import best_time, markdown_table, write_results

REPO = Path(__file__).resolve().parents[1]
L0B = Path(os.environ.get("SARCLI_SHARED", REPO.parent / "shared")) / "data" / "alos_palsar_l0b" / \
    "ALPSRP264757150-H1.0__A_HH_LINE4000-5000_RANGE0-2200.h5"
IMAGES = REPO / "docs" / "images"
SCENE = REPO / "tests" / "nisar" / "scenes" / "cr_points.toml"
REDUCED_BAND_HZ = 150.0


def _sensitivity(raw, model, dp_deg: float = 0.01) -> dict:
    """Change of the predicted centroid (Hz) at the scene centre for +dp of pitch, and of yaw."""
    import dataclasses

    from sarcli.doppler.geometry import OrbitGeometry

    r = float(raw.slant_range()[raw.shape[1] // 2])
    t = float(np.mean(raw.azimuth_time))
    base = float(OrbitGeometry.from_raw(raw).fdc_vector(r, t))
    a = raw.attitude
    out = {}
    for name in ("pitch", "yaw"):
        moved = dataclasses.replace(a, **{name: getattr(a, name) + np.radians(dp_deg)})
        g = OrbitGeometry.from_raw(dataclasses.replace(raw, attitude=moved))
        out[f"hz_per_0.01deg_{name}"] = float(g.fdc_vector(r, t)) - base
    return out


def _real(md: list[str], data: dict, tmp: Path) -> None:
    from sarcli.calibration.pointing import centroid_comparison
    from sarcli.doppler.api import estimate_doppler
    from sarcli.doppler.options import DopplerOptions
    from sarcli.focus.quicklook import write_slc_quicklook
    from sarcli.focus.rangecomp import range_compress
    from sarcli.focus.rda import focus_rd
    from sarcli.io.images import write_quicklook
    from sarcli.io.nisar.l0b import read_l0b
    from sarcli.io.nisar.rslc import read_rslc
    from sarcli.workflows.export import write_format

    t_read = best_time(lambda: read_l0b(L0B), repeat=3)
    raw = read_l0b(L0B).products["A_HH"]
    model = estimate_doppler(raw, DopplerOptions(az_block=250, ambiguity="data"))
    c = centroid_comparison(model)
    sens = _sensitivity(raw, model)
    do = {e["method"]: e for e in c.pop("data_only")}
    data["l0b"] = {"read_s": t_read, "shape": list(raw.shape), "centroid": c, "sensitivity": sens,
                   "data_only": {k: {kk: v[kk] for kk in ("fdc_hz", "sigma_hz", "ambiguity", "confidence")}
                                 for k, v in do.items()}}
    md += ["## Real ALOS-1 PALSAR L0B cut (1000 lines x 2200 samples, HH)", "",
           f"read_l0b: {t_read:.3f} s (best of 3, warm cache; 8.8 MB of codes).", "",
           markdown_table(["quantity", "value"], [
               ["baseband centroid, data (CDE, 68 blocks of 250 x 128)", f"{c['fdc_baseband_data_hz']:.2f} Hz"],
               ["standard error (block scatter)", f"{c['sigma_scatter_hz']:.2f} Hz"],
               ["standard error (CDE phase variance)", f"{c['sigma_model_hz']:.2f} Hz"],
               ["centroid predicted from orbit + attitude quaternions", f"{c['fdc_predicted_hz']:.2f} Hz"],
               ["data minus predicted", f"{c['data_minus_predicted_hz']:+.2f} Hz"],
               ["predicted change for +0.01 deg pitch / yaw",
                f"{sens['hz_per_0.01deg_pitch']:+.2f} / {sens['hz_per_0.01deg_yaw']:+.2f} Hz"],
               ["ambiguity: orbit + attitude / data (source, confidence)",
                f"{c['ambiguity_prediction']} / {c['ambiguity']} ({c['ambiguity_source']}, "
                f"{c['ambiguity_confidence']:.6f})"],
               ["MLCC absolute centroid", f"{do['mlcc']['fdc_hz']:.0f} +- {do['mlcc']['sigma_hz']:.0f} Hz"],
               ["MLBF absolute centroid", f"{do['mlbf']['fdc_hz']} (sigma {do['mlbf']['sigma_hz']})"],
           ]), ""]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        slc = focus_rd(raw, model)
        t_focus = time.perf_counter() - t0
        red = focus_rd(raw, model, azimuth_bandwidth_hz=REDUCED_BAND_HZ)
    rc = range_compress(raw.echo, raw.radar, raw.replica)
    looks = 5
    inten = np.abs(rc[: rc.shape[0] // looks * looks]).astype(np.float32) ** 2
    inten = inten.reshape(-1, looks, rc.shape[1]).mean(axis=1)
    r = raw.slant_range() / 1e3
    write_quicklook(IMAGES / "nisar_alos_rc.png", np.sqrt(inten), title="ALOS-1 L0B cut, range compressed "
                    f"(replica from the chirp; {looks} azimuth looks)", extent=(r[0], r[-1], raw.azimuth_time[-1],
                                                                               raw.azimuth_time[0]),
                    xlabel="slant range (km)", ylabel="azimuth (pulse) time (s)")
    write_slc_quicklook(IMAGES / "nisar_alos_focused.png", slc, looks_az=looks, title=(
        f"ALOS-1 L0B cut, RDA over 0.8 PRF: partially focused ({raw.shape[0]} of "
        f"{slc.parameters['aperture_lines']:.0f} aperture lines)"))
    from sarcli.calibration.irf import band_grid, window_irw_factor, window_values
    from sarcli.focus.quality import azimuth_ground_spacing

    ds = azimuth_ground_spacing(slc)
    k = window_irw_factor(window_values("kaiser:2.5", band_grid()))
    vg = ds * raw.radar.prf_hz
    frac = raw.shape[0] / slc.parameters["aperture_lines"]
    out = tmp / "alos_rslc.h5"
    t0 = time.perf_counter()
    write_format(slc, out, "nisar-rslc", {"mission_id": "ALOS", "instrument": "PALSAR"}, (L0B,))
    t_w = time.perf_counter() - t0
    back = read_rslc(out)
    data["focus"] = {"aperture_lines": slc.parameters["aperture_lines"], "first_full_line": slc.first_full_line,
                     "last_full_line": slc.last_full_line, "focus_s": t_focus, "ground_speed_mps": vg,
                     "full_band_irw_m": k * vg / slc.parameters["azimuth_bandwidth_hz"], "aperture_fraction": frac,
                     "reduced_band_hz": REDUCED_BAND_HZ, "reduced_first_full": red.first_full_line,
                     "reduced_last_full": red.last_full_line, "reduced_irw_m": k * vg / REDUCED_BAND_HZ,
                     "rslc_write_s": t_w, "rslc_mb": out.stat().st_size / 1e6,
                     "rslc_round_trip_exact": bool(np.array_equal(back.image, slc.image))}
    f = data["focus"]
    md += ["Focusing (RDA, Kaiser 2.5 windows):", "",
           markdown_table(["processed azimuth band", "aperture (lines)", "fully focused lines",
                           "azimuth IRW (theory)"], [
               [f"{slc.parameters['azimuth_bandwidth_hz']:.0f} Hz (0.8 PRF)", f"{f['aperture_lines']:.0f}",
                "none" if slc.first_full_line > slc.last_full_line else f"{slc.first_full_line}..{slc.last_full_line}",
                f"{f['full_band_irw_m']:.2f} m if whole; the best line has {100 * frac:.1f} % of its aperture"],
               [f"{REDUCED_BAND_HZ:.0f} Hz", f"{red.parameters['aperture_lines']:.0f}",
                f"{red.first_full_line}..{red.last_full_line}", f"{f['reduced_irw_m']:.1f} m"],
           ]), "",
           f"Ground speed {vg:.0f} m/s; RDA {t_focus:.2f} s; RSLC export {t_w:.2f} s, {f['rslc_mb']:.1f} MB, read back "
           f"exactly: {f['rslc_round_trip_exact']}.", ""]


def _simulated(md: list[str], data: dict, tmp: Path) -> None:
    from sarcli.calibration.analysis import analyse
    from sarcli.calibration.plots import plot_reflector
    from sarcli.calibration.reflectors import CornerReflector, parse_reflectors, write_reflectors
    from sarcli.focus.rda import focus_rd
    from sarcli.io.nisar.rslc import read_rslc
    from sarcli.model.doppler import GeometricDoppler
    from sarcli.sim.scene import load_scene
    from sarcli.sim.stripmap import simulate
    from sarcli.workflows.export import write_format

    raw = simulate(load_scene(SCENE))
    r = raw.slant_range()
    k = r.size // 2
    dop = GeometricDoppler.from_centroid_and_rate(float(raw.truth["doppler_centroid_hz"][k]),
                                                  float(raw.truth["doppler_rate_hz_per_s"][k]), float(r[k]),
                                                  raw.radar.wavelength_m)
    slc = focus_rd(raw, dop, azimuth_bandwidth_hz=900.0)
    rslc = tmp / "sim_rslc.h5"
    write_format(slc, rslc, "nisar-rslc")
    crs = [CornerReflector(f"T{int(t['id'])}", float(t["lat_deg"]), float(t["lon_deg"]), float(t["height_m"]),
                           180.0, 10.0, 2.8) for t in raw.truth["targets"]]
    csv = tmp / "targets.csv"
    write_reflectors(csv, crs)
    s = read_rslc(rslc)
    a = analyse(s, parse_reflectors(csv))
    rows = [[x.id, f"{x.range_offset_px:+.4f}", f"{x.azimuth_offset_px:+.4f}",
             f"{x.range_irw_m:.3f} / {x.range_irw_theory_m:.3f}",
             f"{x.azimuth_irw_m:.3f} / {x.azimuth_irw_theory_m:.3f}",
             f"{x.range_pslr_db:.2f}", f"{x.azimuth_pslr_db:.2f}"] for x in a.results]
    data["simulated"] = [x.record() | {"range_offset_px": x.range_offset_px, "azimuth_offset_px": x.azimuth_offset_px,
                                       "range_irw_theory_m": x.range_irw_theory_m,
                                       "azimuth_irw_theory_m": x.azimuth_irw_theory_m} for x in a.results]
    plot_reflector(IMAGES / "nisar_cr_sim.png", s.image, a.results[0], float(s.slant_range[1] - s.slant_range[0]),
                   title="simulated C-band point target T0 read back from the NISAR RSLC")
    md += ["## Simulated point targets written as an RSLC, found from a corner-reflector CSV", "",
           "tests/nisar/scenes/cr_points.toml, RDA with the scene's geometric Doppler over 900 Hz (inside the "
           "992 Hz illuminated band), Kaiser 2.5 in both axes.", "",
           markdown_table(["target", "range offset (px)", "azimuth offset (px)", "range IRW / theory (m)",
                           "azimuth IRW / theory (m)", "PSLR rg (dB)", "PSLR az (dB)"], rows), ""]


def _external(md: list[str], data: dict) -> None:
    from sarcli.calibration.analysis import analyse
    from sarcli.calibration.reflectors import parse_reflectors
    from sarcli.io.nisar.rslc import read_rslc

    path, csv = os.environ.get("SARCLI_RSLC"), os.environ.get("SARCLI_RSLC_CSV")
    if not (path and csv):
        return
    a = analyse(read_rslc(path), parse_reflectors(csv))
    data["external"] = {"file": Path(path).name, "records": [x.record() for x in a.results],
                        "theory_range_irw_m": a.range_theory.irw, "notes": a.notes}
    md += [f"## {Path(path).name} with {Path(csv).name}", "",
           markdown_table(["id", "range offset (m)", "azimuth offset (m)", "range IRW (m)", "azimuth IRW (m)",
                           "range IRW theory (m)", "azimuth IRW theory (m)"],
                          [[x.id, f"{x.range_offset_m:+.3f}", f"{x.azimuth_offset_m:+.3f}", f"{x.range_irw_m:.2f}",
                            f"{x.azimuth_irw_m:.2f}", f"{x.range_irw_theory_m:.2f}", f"{x.azimuth_irw_theory_m:.2f}"]
                           for x in a.results]), "", *[f"- {n}" for n in a.notes], ""]


def main() -> None:
    md = ["# NISAR L0B / RSLC: real ALOS-1 data and simulated targets", ""]
    data: dict = {}
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        if L0B.is_file():
            _real(md, data, tmp)
        else:
            md += [f"Real-data section NOT RUN: {L0B} is absent.", ""]
        _simulated(md, data, tmp)
        _external(md, data)
    write_results("bench_nisar", "\n".join(md), data)


if __name__ == "__main__":
    main()
