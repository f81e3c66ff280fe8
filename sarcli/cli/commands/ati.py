"""``sarcli ati detect|estimate|compensate|montecarlo``: SAR-ATI ground moving targets (seed 001)."""

from __future__ import annotations

import math
from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, make_typer, progress_bar
from sarcli.errors import SarcliError

ati_app = make_typer(help="SAR along-track interferometry: detect, estimate, compensate ground movers.")

_ROUTE = typer.Option("exact", "--route", help="Estimation route: exact (closed-form geometry, default), "
                                               "nonlinear (full fit of the exact histories), seed (paper's chain).")
_UNWRAP = typer.Option("dechirp", "--unwrap", help="Phase unwrapping: dechirp (model-guided, robust) or itoh.")
_BIN = typer.Option("track", "--bin", help="Range bin: track (per-line peak near the ANV bin) or anv (seed: one bin).")
_PFA = typer.Option(1e-6, "--pfa", help="False-alarm probability per pixel of each CFAR test (magnitude, phase).")


def _load(raw_path: Path):
    from sarcli.io.raw import read_raw

    raw = read_raw(raw_path)
    if raw.n_channels < 2:
        raise SarcliError(f"{raw_path}: has {raw.n_channels} channel; ATI needs two (simulate with second_channel)")
    return raw


def _knobs(pfa: float):
    from sarcli.ati.detect import CfarKnobs

    if not 0.0 < pfa < 0.1:
        raise SarcliError(f"--pfa must be in (0, 0.1), got {pfa}")
    return CfarKnobs(pfa_magnitude=pfa, pfa_phase=pfa)


def _write(out: Path, raw_path: Path, pair, summary: dict, movers: list[dict], after=None, params=None) -> None:
    import numpy as np

    from sarcli.io.ati_product import write_ati

    write_ati(out, epoch_utc=pair.slc0.epoch_utc, t_ref_s=pair.t_ref, look_side=pair.slc0.look_side,
              azimuth_time=pair.slc0.azimuth_time, slant_range=pair.slc0.slant_range, image_before=pair.z0,
              ati_phase=np.angle(pair.z1 * np.conj(pair.z0)), movers=movers, detection=summary,
              image_after=after, parameters=params or {}, inputs=(raw_path,))
    info(f"wrote {out}")


@ati_app.command("detect")
def detect_cmd(
    raw_path: Path = typer.Argument(..., help="Two-channel raw product (HDF5) of a straight flight (LOCAL frame)."),
    output: Path = typer.Option(None, "-o", "--output", help="Write an ATI product (images, ATI phase, candidates)."),
    pfa: float = _PFA,
    as_json: bool = typer.Option(False, "--json", help="Print the candidates as JSON on stdout."),
) -> None:
    """RD-focus both channels, co-register, form the ATI interferogram and detect movers.

    CFAR on magnitude and on the ATI phase (thermal phase noise of each pixel plus a systematic
    floor); clusters become candidates with their ATI phase, LOS speed, ground-range speed vx and a
    confidence. A phase near +-pi is flagged as a velocity ambiguity.

    Examples:

      sarcli simulate samples/ati_paper.toml -o raw2ch.h5

      sarcli ati detect raw2ch.h5

      sarcli ati detect raw2ch.h5 --pfa 1e-5 --json -o detect.h5
    """
    from sarcli.ati.pipeline import detect_pair, focus_pair

    raw = _load(raw_path)
    pair = focus_pair(raw)
    cands, summary = detect_pair(pair, _knobs(pfa))
    rows = [c.as_dict() for c in cands]
    for c in cands:
        info(f"mover {c.id}: t = {c.azimuth_time_s:.4f} s, R = {c.slant_range_m:.1f} m, ATI phase "
             f"{c.ati_phase_rad:+.4f} rad, vx = {c.vx_mps:+.2f} m/s, confidence {c.confidence:.3f}"
             + (" (AMBIGUOUS: phase near +-pi)" if c.ati_ambiguous else ""))
    info(f"{len(cands)} candidate(s); bright-mover LOS speed floor {summary['min_vr_los_bright_mps']:.2f} m/s, "
         f"blind speed {summary['blind_speed_mps']:.1f} m/s")
    if output is not None:
        _write(output, raw_path, pair, summary, rows, params={"command": "detect", "pfa": pfa})
    if as_json:
        emit_json({"candidates": rows, "summary": summary})


def _check(route: str, unwrap: str, bin_mode: str, method: str = "exact") -> None:
    """Refuse unknown knob values before any heavy work."""
    from sarcli.ati.estimate import ROUTES
    from sarcli.ati.pipeline import BIN_MODES, COMPENSATIONS
    from sarcli.ati.unwrap import METHODS

    for name, v, allowed in (("--route", route, ROUTES), ("--unwrap", unwrap, METHODS), ("--bin", bin_mode, BIN_MODES),
                             ("--method", method, COMPENSATIONS)):
        if v not in allowed:
            raise SarcliError(f"{name} {v!r}: choose one of {', '.join(allowed)}")


def _estimate(raw_path: Path, route: str, unwrap: str, bin_mode: str, pfa: float):
    from sarcli.ati.pipeline import process

    _check(route, unwrap, bin_mode)
    raw = _load(raw_path)
    pair, summary, results = process(raw, route, unwrap, bin_mode, _knobs(pfa))
    for f in summary["estimation_failures"]:
        info(f"mover {f['id']}: estimation failed: {f['error']}")
    return raw, pair, summary, results


def _print_mover(d: dict) -> None:
    flags = [k for k in ("ati_ambiguous", "vy_degenerate") if d[k]]
    info(f"mover {d['id']}: vx {d['vx_mps']:+.3f} +- {d['vx_mps_sigma']:.3f} m/s, vy {d['vy_mps']:+.3f} +- "
         f"{d['vy_mps_sigma']:.3f} m/s, x0 {d['x0_m']:.2f} +- {d['x0_m_sigma']:.2f} m, y0 {d['y0_m']:.2f} +- "
         f"{d['y0_m_sigma']:.2f} m, R0 {d['r0_m']:.2f} m" + (f" [{', '.join(flags)}]" if flags else ""))


@ati_app.command("estimate")
def estimate_cmd(
    raw_path: Path = typer.Argument(..., help="Two-channel raw product (HDF5); detection runs first."),
    route: str = _ROUTE,
    unwrap: str = _UNWRAP,
    bin_mode: str = _BIN,
    pfa: float = _PFA,
    output: Path = typer.Option(None, "-o", "--output", help="Write an ATI product with the movers table."),
    as_json: bool = typer.Option(False, "--json", help="Print the movers as JSON on stdout."),
) -> None:
    """Estimate vx, vy, x0, y0 (and R0) of every detected mover, each with a 1-sigma uncertainty.

    Per mover: sub-image cut, inverse azimuth compression, ANV range bin, phase unwrapping,
    weighted LS fit with covariance, then the chosen route. Positions x0, y0 are relative to the
    platform at the reference time t_ref (scene centre); x_local_m, y_local_m are in the LOCAL frame.

    Examples:

      sarcli ati estimate raw2ch.h5

      sarcli ati estimate raw2ch.h5 --route nonlinear --json

      sarcli ati estimate raw2ch.h5 --route seed --bin anv --unwrap itoh --json
    """
    _, pair, summary, results = _estimate(raw_path, route, unwrap, bin_mode, pfa)
    movers = [r.as_dict() for r in results]
    for d in movers:
        _print_mover(d)
    if output is not None:
        _write(output, raw_path, pair, summary, movers,
               params={"command": "estimate", "route": route, "unwrap": unwrap, "bin": bin_mode, "pfa": pfa})
    if as_json:
        emit_json(movers)


def _true_window(pair, res, half_rows: int = 90, half_cols: int = 3) -> tuple[slice, slice]:
    """Rows/columns around the mover's estimated true position (where the compensation puts it)."""
    import numpy as np

    t = pair.slc0.azimuth_time
    row = int(np.argmin(np.abs(t - (pair.t_ref + res.estimate.y0_m / pair.platform.speed))))
    col = int(np.argmin(np.abs(pair.slc0.slant_range - math.hypot(res.estimate.x0_m, pair.platform.height))))
    n, m = pair.z0.shape
    return (slice(max(0, row - half_rows), min(n, row + half_rows + 1)),
            slice(max(0, col - half_cols), min(m, col + half_cols + 1)))


def _truth_movers(raw) -> list[dict]:
    tab = (raw.truth or {}).get("targets")
    if tab is None:
        return []
    return [{"x_m": float(r["x_m"]), "y_m": float(r["y_m"]),
             "moving": bool(abs(r["vel_x_mps"]) + abs(r["vel_y_mps"]) > 0)} for r in tab]


@ati_app.command("compensate")
def compensate_cmd(
    raw_path: Path = typer.Argument(..., help="Two-channel raw product (HDF5); detection and estimation run first."),
    output: Path = typer.Option(..., "-o", "--output", help="ATI product with image_before and image_after."),
    method: str = typer.Option("exact", "--method", help="Compensation: exact (R - Rs), quadratic (seed eq. 20), "
                                                         "conventional (neglects vy*y0/R0)."),
    compare_conventional: bool = typer.Option(True, "--compare/--no-compare",
                                              help="Also measure the conventional method (position error)."),
    png_dir: Path = typer.Option(None, "--png-dir", help="Write before/after images and azimuth PSF plots here."),
    route: str = _ROUTE,
    unwrap: str = _UNWRAP,
    bin_mode: str = _BIN,
    pfa: float = _PFA,
    as_json: bool = typer.Option(False, "--json", help="Print per-mover positions and PSF widths as JSON."),
) -> None:
    """Compensate each mover (H_ph on its slow-time signal, re-compression) and relocate it.

    The compensated mover is placed at its estimated true position (azimuth y0, range
    sqrt(x0^2 + H^2)); the report gives its peak position, -3 dB azimuth width, the conventional
    method's position for comparison, and errors against the truth when the product is simulated.
    LOCAL-frame scenes are not geolocated: no GeoTIFF is written for them.

    Examples:

      sarcli ati compensate raw2ch.h5 -o comp.h5 --png-dir figs

      sarcli ati compensate raw2ch.h5 -o comp.h5 --method quadratic --json
    """
    from sarcli.ati.pipeline import centroid_row, compensate, peak_position, psf_cut, width_3db

    _check(route, unwrap, bin_mode, method)
    raw, pair, summary, results = _estimate(raw_path, route, unwrap, bin_mode, pfa)
    t = pair.slc0.azimuth_time
    dt = float(t[1] - t[0])
    vp = pair.platform.speed

    def y_of(row: float) -> float:
        return pair.origin_xy[1] + (float(t[0]) + row * dt - pair.t_ref) * vp

    after = pair.z0
    report, movers = [], []
    truth = _truth_movers(raw)
    for res in results:
        d = res.as_dict()
        movers.append(d)
        comp = compensate(pair, res, method)
        after = comp if after is pair.z0 else after + (comp - pair.z0)  # several movers: add each change
        win_r, win_c = _true_window(pair, res)
        r, c, cut = psf_cut(after, win_r, win_c)
        rb, cb, cut_b = psf_cut(pair.z0, res.rows, res.cols)
        rec = {"id": d["id"], "method": method, "peak_y_local_m": y_of(peak_position(cut, r)),
               "peak_range_m": float(pair.slc0.slant_range[c]), "width_3db_m": width_3db(cut, r) * dt * vp,
               "before_peak_y_local_m": y_of(peak_position(cut_b, rb)),
               "before_width_3db_m": width_3db(cut_b, rb) * dt * vp,
               "before_centroid_y_local_m": y_of(centroid_row(pair.z0, res.rows, res.cols)),
               "estimated_y_local_m": d["y_local_m"]}
        if compare_conventional:
            conv = compensate(pair, res, "conventional")
            rc, cc, cut_c = psf_cut(conv, win_r, win_c)
            rec["conventional_peak_y_local_m"] = y_of(peak_position(cut_c, rc))
        movers_truth = [m for m in truth if m["moving"]]
        if movers_truth:
            best = min(movers_truth, key=lambda m: abs(m["y_m"] - d["y_local_m"]) + abs(m["x_m"] - d["x_local_m"]))
            rec["true_y_local_m"] = best["y_m"]
            rec["position_error_m"] = rec["peak_y_local_m"] - best["y_m"]
            rec["before_displacement_m"] = rec["before_centroid_y_local_m"] - best["y_m"]
            if compare_conventional:
                rec["conventional_position_error_m"] = rec["conventional_peak_y_local_m"] - best["y_m"]
        report.append(rec)
        info(f"mover {d['id']}: before at y = {rec['before_peak_y_local_m']:.1f} m "
             f"(width {rec['before_width_3db_m']:.1f} m),"
             f" after ({method}) at y = {rec['peak_y_local_m']:.2f} m (width {rec['width_3db_m']:.2f} m)"
             + (f", conventional at y = {rec['conventional_peak_y_local_m']:.2f} m" if compare_conventional else ""))
        if png_dir is not None:
            _pngs(png_dir, pair, res, after, conv if compare_conventional else None, d["id"], y_of)
    _write(output, raw_path, pair, summary, movers, after=after,
           params={"command": "compensate", "method": method, "route": route, "unwrap": unwrap, "bin": bin_mode})
    if as_json:
        emit_json({"movers": movers, "compensation": report})


def _pngs(folder: Path, pair, res, after, conv, mid: int, y_of) -> None:
    import numpy as np

    from sarcli.ati.pipeline import psf_cut
    from sarcli.ati.plots import psf_plot
    from sarcli.io.images import write_quicklook

    if folder.exists() and not folder.is_dir():
        raise SarcliError(f"--png-dir {folder} is not a folder")
    folder.mkdir(parents=True, exist_ok=True)
    n = pair.z0.shape[0]
    ranges = pair.slc0.slant_range
    cols = slice(max(0, res.cols.start - 20), min(ranges.size, res.cols.stop + 20))
    y_est = res.y_local_m
    ys = np.array([y_of(i) for i in range(n)])
    centre = int(np.argmin(np.abs(ys - y_est)))
    half = max(res.rows.stop - res.rows.start, 120)
    rows = slice(max(0, min(res.rows.start, centre) - half // 2), min(n, max(res.rows.stop, centre) + half // 2))
    ext = [float(ranges[cols.start]), float(ranges[cols.stop - 1]), float(ys[rows.stop - 1]), float(ys[rows.start])]
    kw = {"extent": ext, "xlabel": "slant range (m)", "ylabel": "azimuth y (m)", "dynamic_range_db": 40.0}
    write_quicklook(folder / f"mover{mid}_before.png", pair.z0[rows, cols], title="before compensation", **kw)
    write_quicklook(folder / f"mover{mid}_after.png", after[rows, cols], title="after compensation (proposed)", **kw)
    prof = {}
    _, _, cb = psf_cut(pair.z0, res.rows, res.cols)
    prof["before"] = (ys, cb)
    win_r, win_c = _true_window(pair, res)
    _, _, ca = psf_cut(after, win_r, win_c)
    prof["proposed"] = (ys, ca)
    if conv is not None:
        write_quicklook(folder / f"mover{mid}_conventional.png", conv[rows, cols], title="conventional compensation",
                        **kw)
        _, _, cc = psf_cut(conv, win_r, win_c)
        prof["conventional"] = (ys, cc)
    psf_plot({k: (y[rows], v[rows]) for k, (y, v) in prof.items()}, folder / f"mover{mid}_psf.png",
             f"azimuth PSF, mover {mid}")


@ati_app.command("montecarlo")
def montecarlo_cmd(
    scene: Path = typer.Option(..., "--scene", help="Scene TOML with one moving target (two channels)."),
    runs: int = typer.Option(50, "--runs", help="Runs per SNR."),
    snr: str = typer.Option("-5:25:5", "--snr", help="SNR values (dB): start:stop:step or a comma list."),
    seed: int = typer.Option(1, "--seed", help="Master seed; every run's seed derives from it."),
    route: str = _ROUTE,
    unwrap: str = _UNWRAP,
    bin_mode: str = _BIN,
    plot: Path = typer.Option(None, "--plot", help="Write the Fig. 9-style error plot (PNG)."),
    as_json: bool = typer.Option(False, "--json", help="Print per-SNR mean and max relative errors as JSON."),
) -> None:
    """Relative errors of vy, x0, y0 vs SNR over repeated simulations (reproducible from --seed).

    Each run simulates the scene at the SNR with its own seed, focuses, detects and estimates.

    Examples:

      sarcli ati montecarlo --scene samples/ati_paper.toml --runs 50 --snr -5:25:5 --seed 7 --plot mc.png

      sarcli ati montecarlo --scene samples/ati_paper.toml --runs 3 --snr 10,20 --seed 1 --json
    """
    from sarcli.ati.montecarlo import parse_snr_range, run
    from sarcli.ati.plots import montecarlo_plot

    _check(route, unwrap, bin_mode)
    snrs = parse_snr_range(snr)
    with progress_bar(runs * len(snrs), label="ati montecarlo") as bar:
        result = run(str(scene), runs, snrs, seed, route, unwrap, bin_mode, on_run=lambda: bar.update(1))
    info(f"{'SNR dB':>7} {'vy mean %':>10} {'vy max %':>9} {'x0 mean %':>10} {'x0 max %':>9} {'y0 mean %':>10} "
         f"{'y0 max %':>9} {'missed':>6}")
    for e in result["per_snr"]:
        info(f"{e['snr_db']:7.1f} " + " ".join(
            f"{100 * e[f'{k}_mean_rel']:10.4f} {100 * e[f'{k}_max_rel']:9.4f}" if math.isfinite(e[f"{k}_mean_rel"])
            else f"{'nan':>10} {'nan':>9}" for k in ("vy", "x0", "y0")) + f" {e['missed']:6d}")
    if plot is not None:
        montecarlo_plot(result, plot)
        info(f"wrote {plot}")
    if as_json:
        emit_json(result)


def register(app: typer.Typer) -> None:
    app.add_typer(ati_app, name="ati")
