"""``sarcli orbit info|interpolate|accuracy``: state vectors of a raw product, and what accuracy costs."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, make_typer, report
from sarcli.errors import SarcliError

orbit_app = make_typer(help="Orbit state vectors: summary, Hermite interpolation, accuracy/cost tables.")


def _state_vectors(path: Path):
    """(RawProduct without echo, StateVectors) of a raw product; one-line error if it has no orbit."""
    from orbit.statevectors import StateVectors
    from sarcli.io.raw import read_raw

    raw = read_raw(path, load_echo=False)
    if raw.orbit is None:
        raise SarcliError(f"{path}: product has no /orbit state vectors")
    return raw, StateVectors.from_record(raw.orbit, raw.epoch_utc)


def parse_times(spec: str, epoch_utc: str) -> list[float]:
    """'0,12.5,30' (seconds after the epoch), ranges 'start:stop:step' (stop included if on the grid) and
    ISO-8601 UTC instants ('2002-06-16T15:41:02.5Z'), mixed freely."""
    import numpy as np

    from orbit.timeutil import parse_utc

    out: list[float] = []
    for item in (s.strip() for s in spec.split(",")):
        if not item:
            continue
        try:
            if "T" in item:
                out.append((parse_utc(item) - parse_utc(epoch_utc)).total_seconds())
            elif ":" in item:
                a, b, c = (float(x) for x in item.split(":"))
                if c <= 0 or b < a:
                    raise ValueError
                n = int(np.floor((b - a) / c + 1e-9)) + 1
                if n > 10_000_000:
                    raise SarcliError(f"--times range {item!r} has {n} points (max 10 000 000)")
                out.extend((a + c * np.arange(n)).tolist())
            else:
                out.append(float(item))
        except ValueError:
            raise SarcliError(f"--times: cannot read {item!r}; use numbers (s after the epoch), "
                              "start:stop:step with step > 0, or ISO-8601 UTC times") from None
    if not out:
        raise SarcliError("--times is empty")
    return out


def _scene_geometry(raw, sv, n_samples: int) -> dict:
    """Sub-satellite point, altitude, pass direction and the zero-Doppler look and incidence angles of the
    first and last range samples, at the scene-centre line (ECI/ECEF orbits)."""
    import numpy as np

    from orbit.geodetic import ecef_to_geodetic
    from orbit.geometry import incidence_angle, look_angle, target_from_doppler
    from sarcli.model.constants import C_LIGHT

    svf = sv.to_ecef()
    t = raw.azimuth_time
    inside = t[(t >= sv.span[0]) & (t <= sv.span[1])]
    if inside.size == 0:
        return {}
    tc = float(inside[inside.size // 2])
    r, v, _ = svf.interpolate(tc)
    lat, lon, h = (float(x) for x in ecef_to_geodetic(r))
    up = np.array([np.cos(np.radians(lat)) * np.cos(np.radians(lon)),
                   np.cos(np.radians(lat)) * np.sin(np.radians(lon)), np.sin(np.radians(lat))])
    north = np.array([0.0, 0.0, 1.0]) - up * up[2]
    out = {"scene_center_time_s": tc, "sub_satellite_lat_deg": lat, "sub_satellite_lon_deg": lon,
           "altitude_m": h, "pass": "ascending" if v @ north > 0 else "descending",
           "ecef_speed_mps": float(np.linalg.norm(v))}
    rng = np.array([raw.radar.first_range_m,
                    raw.radar.first_range_m + (n_samples - 1) * C_LIGHT / (2.0 * raw.radar.range_sampling_rate_hz)])
    try:
        p = target_from_doppler(r, v, rng, raw.radar.wavelength_m, 0.0, raw.look_side)
    except ValueError as e:  # the range does not reach the Earth from this orbit: say so, don't fail
        out["geometry_note"] = str(e)
        return out
    rc = np.broadcast_to(r, p.shape)
    out.update(zero_doppler_slant_range_m=rng.tolist(), look_angle_deg=np.degrees(look_angle(rc, p)).tolist(),
               incidence_angle_deg=np.degrees(incidence_angle(rc, p)).tolist())
    return out


@orbit_app.command("info")
def info_cmd(
    raw_path: Path = typer.Argument(..., help="Raw product (HDF5) with /orbit."),
    as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON on stdout."),
) -> None:
    """Summarize a product's state vectors: frame, span, spacing, coverage of the echo, geometry.

    Reports whether every azimuth line lies inside the state-vector span (interpolation refuses times
    outside it), the spacing (non-uniform spacing is fine), the default Hermite order, and for ECI/ECEF
    orbits the altitude, pass direction, and the zero-Doppler look and incidence angles of the first
    (and last) range sample at the scene centre. For ingested CEOS products, the difference between
    the delivered Greenwich hour angle and sarcli's GMST shows which equinox the vectors use.

    Examples:

      sarcli orbit info raw.h5

      sarcli orbit info raw.h5 --json
    """
    import numpy as np

    from orbit.constants import WGS84_A
    from orbit.timeutil import add_seconds
    from sarcli.io.raw import raw_shape

    raw, sv = _state_vectors(raw_path)
    dt = np.diff(sv.time)
    t = raw.azimuth_time
    t0, t1 = sv.span
    s = {
        "path": str(raw_path), "frame": sv.frame, "epoch_utc": raw.epoch_utc, "n_vectors": len(sv),
        "start_utc": add_seconds(raw.epoch_utc, t0), "stop_utc": add_seconds(raw.epoch_utc, t1),
        "span_s": t1 - t0, "spacing_s": sv.spacing, "spacing_min_s": float(dt.min()), "spacing_max_s": float(dt.max()),
        "default_n_nodes": sv.default_n_nodes(),
        "echo_start_s": float(t.min()), "echo_stop_s": float(t.max()),
        "margin_before_s": float(t.min() - t0), "margin_after_s": float(t1 - t.max()),
        "echo_covered": bool(t.min() >= t0 and t.max() <= t1),
        "orbit_radius_m": np.linalg.norm(sv.position, axis=1).tolist(),
    }
    if sv.frame != "LOCAL":
        s["geometry"] = _scene_geometry(raw, sv, raw_shape(raw_path)[1])
    gha = _gha_minus_gmst_deg(raw_path)
    if gha is not None:  # CEOS products: the delivered hour angle tells which equinox the vectors use
        s["gha_minus_gmst_deg"] = gha
        s["gha_minus_gmst_ground_m"] = abs(np.radians(gha)) * WGS84_A
    if as_json:
        emit_json(s)
        return
    report(f"{raw_path}: {s['n_vectors']} state vectors ({s['frame']}), {s['start_utc']} .. {s['stop_utc']}")
    report(f"  spacing {s['spacing_s']:.6g} s (min {s['spacing_min_s']:.6g}, max {s['spacing_max_s']:.6g}); "
         f"Hermite default N = {s['default_n_nodes']}")
    cover = "inside" if s["echo_covered"] else "NOT inside (interpolation will refuse the lines outside)"
    report(f"  echo {s['echo_start_s']:.6f} .. {s['echo_stop_s']:.6f} s: {cover} the span; margins "
         f"{s['margin_before_s']:.1f} s before, {s['margin_after_s']:.1f} s after")
    g = s.get("geometry") or {}
    if "altitude_m" in g:
        report(f"  scene centre t = {g['scene_center_time_s']:.6f} s: {g['pass']} pass, sub-satellite lat "
             f"{g['sub_satellite_lat_deg']:.4f} deg, lon {g['sub_satellite_lon_deg']:.4f} deg, "
             f"altitude {g['altitude_m'] / 1e3:.3f} km, ECEF speed {g['ecef_speed_mps']:.2f} m/s")
    if "look_angle_deg" in g:
        report("  zero-Doppler look / incidence at slant range " + ", ".join(
            f"{r / 1e3:.3f} km: {lk:.4f} / {ic:.4f} deg" for r, lk, ic in
            zip(g["zero_doppler_slant_range_m"], g["look_angle_deg"], g["incidence_angle_deg"], strict=True)))
    if "geometry_note" in g:
        report(f"  geometry: {g['geometry_note']}")
    if "gha_minus_gmst_deg" in s:
        report(f"  frame check: product hour angle - GMST = {s['gha_minus_gmst_deg']:.6f} deg "
             f"({s['gha_minus_gmst_ground_m']:.1f} m at the equator)")


def _gha_minus_gmst_deg(path: Path) -> float | None:
    """The CEOS reader's ``ceos_gha_minus_gmst_deg`` root attribute, if the product has one."""
    import h5py

    with h5py.File(path, "r") as f:
        v = f.attrs.get("ceos_gha_minus_gmst_deg")
    return None if v is None else float(v)


@orbit_app.command("interpolate")
def interpolate_cmd(
    raw_path: Path = typer.Argument(..., help="Raw product (HDF5) with /orbit."),
    times: str = typer.Option(..., "--times", "-t",
                              help="Seconds after the product epoch ('0,10.5', 'start:stop:step') "
                                   "and/or ISO-8601 UTC times."),
    frame: str = typer.Option("native", "--frame", help="Output frame: native (as stored), eci or ecef."),
    n_nodes: int = typer.Option(None, "--n-nodes", "-n", help="Hermite nodes N (2..16); default from the table."),
    extrapolate: float = typer.Option(0.0, "--extrapolate", help="Allow times up to this many s outside the span."),
    csv: Path = typer.Option(None, "--csv", help="Also write the table as CSV (written atomically)."),
    as_json: bool = typer.Option(False, "--json", help="Print the table as JSON on stdout."),
) -> None:
    """Hermite-interpolate the state vectors (positions and velocities) at given times.

    Prints time, position, velocity and acceleration (SI) in the requested frame; in ECEF also the
    geodetic latitude, longitude and height (WGS-84). Times outside the state-vector span are refused
    unless --extrapolate allows them.

    Examples:

      sarcli orbit interpolate raw.h5 --times 0,1.5,3

      sarcli orbit interpolate raw.h5 --times 0:10:0.5 --frame ecef --json

      sarcli orbit interpolate raw.h5 --times 2002-06-16T15:41:02.5Z

      sarcli orbit interpolate raw.h5 --times 0:6720:60 --frame ecef --csv orbit.csv
    """
    import numpy as np

    from orbit.errors import InterpolationRangeError
    from orbit.geodetic import ecef_to_geodetic
    from orbit.timeutil import add_seconds

    frame = frame.lower()
    if frame not in ("native", "eci", "ecef"):
        raise SarcliError(f"--frame must be native, eci or ecef, got {frame!r}")
    raw, sv = _state_vectors(raw_path)
    if frame == "ecef":
        sv = sv.to_ecef()
    elif frame == "eci":
        sv = sv.to_eci()
    t = np.array(parse_times(times, raw.epoch_utc))
    try:
        p, v, a = sv.interpolate(t, n_nodes, max_extrapolation_s=extrapolate)
    except InterpolationRangeError as e:
        raise SarcliError(str(e).split(" (pass ")[0] + (" (use --extrapolate SECONDS to allow a bounded "
                                                         "extrapolation)" if not extrapolate else "")) from None
    cols = {"time_s": t, "x_m": p[:, 0], "y_m": p[:, 1], "z_m": p[:, 2], "vx_mps": v[:, 0], "vy_mps": v[:, 1],
            "vz_mps": v[:, 2], "ax_mps2": a[:, 0], "ay_mps2": a[:, 1], "az_mps2": a[:, 2]}
    if sv.frame == "ECEF":
        cols["lat_deg"], cols["lon_deg"], cols["h_m"] = ecef_to_geodetic(p)
    N = sv.default_n_nodes() if n_nodes is None else n_nodes
    t0, t1 = sv.span
    outside = np.flatnonzero((t < t0) | (t > t1))
    if outside.size:
        shown = ", ".join(f"{x:.6f}" for x in t[outside[:8]]) + (", ..." if outside.size > 8 else "")
        info(f"warning: extrapolated {outside.size} of {t.size} time(s) beyond the state-vector span "
             f"[{t0:.6f}, {t1:.6f}] s: {shown}")
    if csv is not None:
        _write_csv(csv, cols)
    if as_json:
        emit_json({"path": str(raw_path), "frame": sv.frame, "epoch_utc": raw.epoch_utc, "n_nodes": N,
                   "span_s": [t0, t1], "extrapolated_time_s": t[outside].tolist(),
                   "utc": [add_seconds(raw.epoch_utc, x) for x in t[:10000]] if t.size <= 10000 else None,
                   **{k: c.tolist() for k, c in cols.items()}})
        return
    if csv is not None:  # the table is in the file: one summary line, not the rows again
        info(f"wrote {csv}: {t.size} row(s), {sv.frame}, Hermite N = {N}, t {t.min():.6f}..{t.max():.6f} s, "
             f"columns {', '.join(cols)}")
        return
    report(f"{sv.frame}, Hermite N = {N}, {t.size} time(s)")
    head = list(cols)
    report(" ".join(f"{h:>16}" for h in head))
    for i in range(min(t.size, 1000)):
        report(" ".join(f"{cols[h][i]:16.6f}" for h in head))
    if t.size > 1000:
        report(f"... {t.size - 1000} more rows (use --csv or --json)")


def _write_csv(path: Path, cols: dict) -> None:
    import numpy as np

    from sarcli.io.images import atomic_path

    table = np.column_stack(list(cols.values()))
    with atomic_path(path, ".csv") as tmp:
        np.savetxt(tmp, table, delimiter=",", header=",".join(cols), comments="", fmt="%.10f")


@orbit_app.command("accuracy")
def accuracy_cmd(
    plot: Path = typer.Option(None, "--plot", help="Write a PNG of position/velocity error vs time per N."),
    as_json: bool = typer.Option(False, "--json", help="Print the tables as JSON on stdout."),
    timing: bool = typer.Option(True, "--timing/--no-timing", help="Measure evaluations per CPU second."),
) -> None:
    """Accuracy vs cost of the orbit knobs, computed now (a few seconds).

    Hermite order N = 2..12 against a J2-integrated Radarsat-1-like truth sampled 15 x 480 s (max
    position and velocity error away from the span ends and in the end intervals, evaluations per CPU
    second); exact vs small-angle attitude rotation at 0, 1, 10, 100 x the Radarsat-1 limits
    (pointing error, Doppler error, ground error); the Earth-frame model differences in metres at the
    ground.

    Examples:

      sarcli orbit accuracy

      sarcli orbit accuracy --plot orbit_accuracy.png --json
    """
    from orbit import accuracy as A

    truth = A.rs1_truth()
    result = {"hermite": A.hermite_table(truth=truth, timing=timing, n_times=200_000),
              "truth_floor": A.truth_floor(truth), "attitude": A.attitude_table(truth=truth),
              "frames": A.frame_table()}
    if plot is not None:
        _accuracy_plot(plot, truth)
        info(f"wrote {plot}")
    if as_json:
        emit_json(result)
        return
    report("Hermite interpolation, 15 x 480 s J2 truth (interior = >= 2 spacings from the ends):")
    report(f"{'N':>3} {'pos int. m':>11} {'vel int. m/s':>13} {'pos ends m':>11} {'vel ends m/s':>13}"
         + (f" {'M evals/s':>10}" if timing else ""))
    for r in result["hermite"]:
        report(f"{r['n_nodes']:3d} {r['pos_err_interior_m']:11.3g} {r['vel_err_interior_mps']:13.3g} "
             f"{r['pos_err_ends_m']:11.3g} {r['vel_err_ends_mps']:13.3g}"
             + (f" {r['evals_per_s'] / 1e6:10.1f}" if timing else ""))
    fl = result["truth_floor"]
    report(f"  (truth floor {fl['pos_m']:.2g} m, {fl['vel_mps']:.2g} m/s)")
    report("Control rotation, exact vs small-angle (x Radarsat-1 limits pitch 0.03 deg, yaw 0.004 deg):")
    for r in result["attitude"]:
        report(f"  x{r['scale']:<5g} pointing {r['pointing_err_urad']:10.4g} urad, "
             f"Doppler {r['doppler_err_hz']:10.4g} Hz, ground {r['ground_err_m']:10.4g} m")
    report("Earth frame model, metres at the ground:")
    for r in result["frames"]:
        report(f"  {r['hypothesis']:<48} {r['ground_m']:10.1f} m")


def _accuracy_plot(path: Path, truth) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from sarcli.io.images import atomic_path

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 7), sharex=True, dpi=100)
    for N in (2, 4, 6, 8, 10, 12):
        p, v, _ = truth.sv.interpolate(truth.t, N)
        ax1.semilogy(truth.t, np.maximum(np.linalg.norm(p - truth.r, axis=1), 1e-9), lw=0.8, label=f"N = {N}")
        ax2.semilogy(truth.t, np.maximum(np.linalg.norm(v - truth.v, axis=1), 1e-12), lw=0.8)
    for ax in (ax1, ax2):
        for tn in truth.sv.time:
            ax.axvline(tn, color="0.85", lw=0.5, zorder=0)
    ax1.axhline(1e-3, color="k", ls="--", lw=0.8)
    ax2.axhline(1e-6, color="k", ls="--", lw=0.8)
    ax1.set_ylabel("position error (m)")
    ax2.set_ylabel("velocity error (m/s)")
    ax2.set_xlabel("time after first state vector (s); grey: nodes; dashed: acceptance bars")
    ax1.set_title("Hermite interpolation of 15 x 480 s state vectors vs J2 truth")
    ax1.legend(ncol=3, fontsize=8)
    fig.tight_layout()
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)


def register(app: typer.Typer) -> None:
    app.add_typer(orbit_app, name="orbit")
