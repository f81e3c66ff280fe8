"""The live status page ``CAMPAIGN/index.html``: one self-contained file (no CDN, no server: maps as
PNG data URIs, charts as inline SVG, a few lines of inline JavaScript), rewritten atomically after
each scan.

It shows the latest scan (number, time, status, the highest alarm level), the instrument's health
(last scan, accepted / rejected / failed scans, last problem), the latest displacement, velocity and
coherence maps in the slant geometry of the rail (azimuth x across, range R0 up: the radar is at the
bottom) with the areas and watch points drawn, the displacement map on the local east/north grid when
the site is georeferenced, time series at the watch points and areas with the alarm thresholds drawn,
the APS residual on the stable points (with and without the correction), the median coherence, the
refractivity from the meteo file beside the one the APS implies, the area levels with the
inverse-velocity forecast, and the alarm list. The inline script records any JavaScript error in
``#js-errors``, shows how old the page is, reloads it every ``refresh_s`` and sets
``<body data-ready="1">`` when it has run (what the headless-browser test checks).
"""

from __future__ import annotations

import base64
import html
import json
import math
import struct
import zlib
from typing import Any

import numpy as np

from sarcli.monitor.config import LEVELS, MonitorConfig
from sarcli.monitor.engine import State, Static

LEVEL_COLOURS = {"none": "#2e7d32", "attention": "#f9a825", "pre-alarm": "#ef6c00", "alarm": "#c62828"}
SERIES_COLOURS = ("#1565c0", "#c62828", "#2e7d32", "#6a1b9a", "#ef6c00", "#00838f", "#5d4037", "#ad1457")


def png_bytes(rgba: np.ndarray) -> bytes:
    """A PNG (8-bit RGBA, no filter) of an (h, w, 4) uint8 array."""
    h, w, _ = rgba.shape
    raw = b"".join(b"\x00" + rgba[i].tobytes() for i in range(h))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def _ramp(x: np.ndarray, stops: list[tuple[float, tuple[int, int, int]]]) -> np.ndarray:
    pos = np.array([s[0] for s in stops])
    cols = np.array([s[1] for s in stops], np.float64)
    xc = np.clip(np.nan_to_num(x), 0, 1)
    return np.stack([np.interp(xc, pos, cols[:, i]) for i in range(3)], -1)


DIVERGING = [(0.0, (33, 102, 172)), (0.25, (103, 169, 207)), (0.5, (247, 247, 247)), (0.75, (239, 138, 98)),
             (1.0, (178, 24, 43))]
SEQUENTIAL = [(0.0, (68, 1, 84)), (0.25, (59, 82, 139)), (0.5, (33, 145, 140)), (0.75, (94, 201, 98)),
              (1.0, (253, 231, 37))]


def colour_map(values: np.ndarray, show: np.ndarray, background: np.ndarray, vmin: float, vmax: float,
               diverging: bool) -> np.ndarray:
    """RGBA (rows flipped so that far range is at the top): ``values`` coloured where ``show``, the grey
    ``background`` (0..1) elsewhere, transparent where the background is NaN."""
    x = (values - vmin) / (vmax - vmin) if vmax > vmin else np.full(values.shape, 0.5)
    rgb = _ramp(x, DIVERGING if diverging else SEQUENTIAL)
    grey = np.repeat(np.clip(np.nan_to_num(background), 0, 1)[..., None] * 160 + 40, 3, -1)
    ok = show & np.isfinite(values)
    out = np.where(ok[..., None], rgb, grey)
    alpha = np.where(np.isfinite(background) | ok, 255, 0)
    return np.concatenate([out, alpha[..., None]], -1).astype(np.uint8)[::-1]


def data_uri(rgba: np.ndarray) -> str:
    return "data:image/png;base64," + base64.b64encode(png_bytes(rgba)).decode("ascii")


def _nice_ticks(lo: float, hi: float, n: int = 5) -> list[float]:
    if not (math.isfinite(lo) and math.isfinite(hi)) or hi <= lo:
        return [lo] if math.isfinite(lo) else []
    raw = (hi - lo) / n
    mag = 10 ** math.floor(math.log10(raw))
    step = next(m * mag for m in (1, 2, 2.5, 5, 10) if m * mag >= raw)
    first = math.ceil(lo / step) * step
    return [first + i * step for i in range(int((hi - first) / step + 1e-9) + 1)]


def _fmt(v: float) -> str:
    return f"{v:.6g}" if abs(v) >= 1e-3 or v == 0 else f"{v:.2e}"


def svg_chart(title: str, t: np.ndarray, series: list[tuple], y_label: str,
              hlines: list[tuple[float, str, str]] = (), width: int = 560, height: int = 230) -> str:
    """A line chart: ``series`` (label, values over ``t``[, colour]: an object keeps its colour in every
    chart), horizontal ``hlines`` (value, colour, label). A series without a finite value gets the note
    "LABEL: no data" instead of a legend entry."""
    ml, mr, mt, mb = 58, 12, 26, 34
    pw, ph = width - ml - mr, height - mt - mb
    vals = [s[1][np.isfinite(s[1])] for s in series]
    ys = np.concatenate(vals + [np.array([h[0] for h in hlines])]) if vals or hlines else np.zeros(0)
    parts = [f'<svg class="chart" viewBox="0 0 {width} {height}" width="{width}" height="{height}" '
             f'role="img" aria-label="{html.escape(title)}">',
             f'<text x="{ml}" y="16" class="ct">{html.escape(title)}</text>']
    if t.size == 0 or ys.size == 0:
        parts.append(f'<text x="{ml + 10}" y="{mt + ph / 2}" class="na">no data yet</text></svg>')
        return "".join(parts)
    y0, y1 = float(ys.min()), float(ys.max())
    pad = 0.08 * (y1 - y0) if y1 > y0 else max(abs(y0) * 0.1, 0.1)
    y0, y1 = y0 - pad, y1 + pad
    x0, x1 = float(t.min()), float(t.max()) if t.max() > t.min() else float(t.min()) + 1.0

    def px(x: float) -> float:
        return ml + (x - x0) / (x1 - x0) * pw

    def py(y: float) -> float:
        return mt + (1 - (y - y0) / (y1 - y0)) * ph

    parts.append(f'<rect x="{ml}" y="{mt}" width="{pw}" height="{ph}" class="frame"/>')
    for yt in _nice_ticks(y0, y1):
        parts.append(f'<line x1="{ml}" x2="{ml + pw}" y1="{py(yt):.1f}" y2="{py(yt):.1f}" class="grid"/>'
                     f'<text x="{ml - 4}" y="{py(yt) + 4:.1f}" class="yt">{_fmt(yt)}</text>')
    for xt in _nice_ticks(x0, x1):
        parts.append(f'<text x="{px(xt):.1f}" y="{mt + ph + 14}" class="xt">{_fmt(xt)}</text>')
    parts.append(f'<text x="{ml + pw / 2}" y="{height - 4}" class="xl">hours since the first scan</text>'
                 f'<text x="12" y="{mt + ph / 2}" class="yl" transform="rotate(-90 12 {mt + ph / 2})">'
                 f'{html.escape(y_label)}</text>')
    for value, colour, label in hlines:
        parts.append(f'<line x1="{ml}" x2="{ml + pw}" y1="{py(value):.1f}" y2="{py(value):.1f}" stroke="{colour}" '
                     f'class="thr"><title>{html.escape(label)} {value:g}</title></line>')
    for k, (label, v, *given) in enumerate(series):
        colour = given[0] if given else SERIES_COLOURS[k % len(SERIES_COLOURS)]
        ok = np.isfinite(v)
        pts = " ".join(f"{px(a):.1f},{py(b):.1f}" for a, b in zip(t[ok], v[ok], strict=True))
        if pts:
            parts.append(f'<polyline points="{pts}" fill="none" stroke="{colour}" stroke-width="1.6">'
                         f'<title>{html.escape(label)}</title></polyline>'
                         f'<text x="{ml + 6 + 110 * k}" y="{mt + 12}" fill="{colour}" class="lg">'
                         f'{html.escape(label)}</text>')
        else:  # a series without a value: a note, not a legend entry for a line that is not there
            parts.append(f'<text x="{ml + 6 + 110 * k}" y="{mt + 12}" class="lg na">{html.escape(label)}: no data'
                         f'</text>')
    parts.append("</svg>")
    return "".join(parts)


def _map_svg(uri: str, static: Static, cfg: MonitorConfig, title: str, unit: str, vmin: float, vmax: float,
             diverging: bool, width: int = 420) -> str:
    """A slant-geometry map: the image, axes in metres, areas (polygons in the image frame) and watch points."""
    az, rg = static.azimuths, static.ranges
    a0, a1, r0, r1 = float(az[0]), float(az[-1]), float(rg[0]), float(rg[-1])
    aspect = (r1 - r0) / (a1 - a0) if a1 > a0 else 1.0
    ml, mb, mt = 46, 30, 22
    pw = width - ml - 70
    ph = int(min(max(pw * aspect, 120), 520))
    height = ph + mt + mb

    def px(a: float) -> float:
        return ml + (a - a0) / (a1 - a0) * pw if a1 > a0 else ml

    def py(r: float) -> float:
        return mt + (1 - (r - r0) / (r1 - r0)) * ph if r1 > r0 else mt

    parts = [f'<svg class="map" viewBox="0 0 {width} {height}" width="{width}" height="{height}" role="img" '
             f'aria-label="{html.escape(title)}"><text x="{ml}" y="14" class="ct">{html.escape(title)}</text>',
             f'<image href="{uri}" x="{ml}" y="{mt}" width="{pw}" height="{ph}" preserveAspectRatio="none" '
             f'style="image-rendering:pixelated"/>',
             f'<rect x="{ml}" y="{mt}" width="{pw}" height="{ph}" class="frame"/>']
    for xt in _nice_ticks(a0, a1, 4):
        parts.append(f'<text x="{px(xt):.1f}" y="{mt + ph + 13}" class="xt">{_fmt(xt)}</text>')
    for yt in _nice_ticks(r0, r1, 5):
        parts.append(f'<text x="{ml - 4}" y="{py(yt) + 4:.1f}" class="yt">{_fmt(yt)}</text>')
    parts.append(f'<text x="{ml + pw / 2}" y="{height - 3}" class="xl">azimuth x (m)</text>'
                 f'<text x="10" y="{mt + ph / 2}" class="yl" transform="rotate(-90 10 {mt + ph / 2})">range R0 (m)'
                 f'</text>')
    for area in cfg.areas:
        if area.polygon is not None and area.frame == "image":
            pts = " ".join(f"{px(a):.1f},{py(r):.1f}" for a, r in area.polygon)
            parts.append(f'<polygon points="{pts}" class="{"stablearea" if area.stable else "area"}">'
                         f'<title>{html.escape(area.name)}</title></polygon>')
    for wp, (r, c) in zip(cfg.watch, static.watch, strict=True):
        x, y = px(float(az[c])), py(float(rg[r]))
        parts.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="4" class="wp"><title>{html.escape(wp.name)}</title>'
                     f'</circle><text x="{x + 6:.1f}" y="{y - 5:.1f}" class="wl">{html.escape(wp.name)}</text>')
    parts.append(_colour_bar(ml + pw + 12, mt, ph, vmin, vmax, diverging, unit) + "</svg>")
    return "".join(parts)


def _colour_bar(bx: float, top: float, ph: float, vmin: float, vmax: float, diverging: bool, unit: str) -> str:
    """A vertical colour bar: its two ends labelled, and the unit in the middle (none for "1": a ratio)."""
    grad = np.linspace(1, 0, 64)[:, None] * np.ones((1, 6))
    bar = colour_map(grad * (vmax - vmin) + vmin, np.ones(grad.shape, bool), grad, vmin, vmax, diverging)[::-1]
    out = (f'<image href="{data_uri(bar)}" x="{bx}" y="{top}" width="12" height="{ph}" '
           f'preserveAspectRatio="none"/><text x="{bx + 15}" y="{top + 9}" class="cb">{vmax:.3g}</text>'
           f'<text x="{bx + 15}" y="{top + ph}" class="cb">{vmin:.3g}</text>')
    if unit != "1":
        out += f'<text x="{bx + 15}" y="{top + ph / 2 + 4}" class="cb">{html.escape(unit)}</text>'
    return out


def _enu_polygon(area, static: Static) -> np.ndarray:
    """(k, 2) east/north vertices of an area's polygon (image frame: azimuth, range R0; site frame: x, y on
    flat ground), each edge densified so that its curvature on the map shows."""
    from sarcli.gbsar.geocode import slant_to_enu

    poly = np.asarray(area.polygon + (area.polygon[0],), np.float64)
    f = np.linspace(0.0, 1.0, 16, endpoint=False)
    dense = np.concatenate([a + f[:, None] * (b - a) for a, b in zip(poly[:-1], poly[1:], strict=True)])
    x, second = dense[:, 0], dense[:, 1]
    h = static.rail_height_m
    r0 = second if area.frame == "image" else np.sqrt(second ** 2 + h ** 2)
    e, n = slant_to_enu(x, r0, static.site, h, static.rail_centre_m)
    return np.column_stack([e, n])


def _geocoded(static: Static, values: np.ndarray, show: np.ndarray, background: np.ndarray, vmax: float,
              cfg: MonitorConfig | None = None) -> str:
    """The displacement on a north-up local east/north grid (the site's tangent plane), or '' when the
    site is not georeferenced."""
    from sarcli.gbsar.geocode import resample_to_map

    site = static.site
    if site.latitude_deg == 0.0 and site.longitude_deg == 0.0:
        return ""
    pixel = float(max(static.ranges[1] - static.ranges[0] if static.ranges.size > 1 else 1.0,
                      static.azimuths[1] - static.azimuths[0] if static.azimuths.size > 1 else 1.0))
    args = (static.ranges, static.azimuths, site, static.rail_height_m, static.rail_centre_m, pixel, "enu")
    vals, transform, _, _ = resample_to_map(np.where(show, values, np.nan).astype(np.float32), *args)
    back, _, _, _ = resample_to_map(background.astype(np.float32), *args)
    rgba = colour_map(vals, np.isfinite(vals), back, -vmax, vmax, True)[::-1]
    h, w = vals.shape
    e0, n1 = transform.c, transform.f
    e1, n0 = e0 + w * transform.a, n1 + h * transform.e
    width = 420
    pw = width - 60 - 50
    ph = int(min(max(pw * (n1 - n0) / (e1 - e0), 120), 520))

    def px(x: float) -> float:
        return 46 + (x - e0) / (e1 - e0) * pw

    def py(y: float) -> float:
        return 22 + (1 - (y - n0) / (n1 - n0)) * ph

    areas = ""
    for area in (cfg.areas if cfg is not None else ()):
        if area.polygon is not None:
            pts = " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y in _enu_polygon(area, static) if np.isfinite(x + y))
            areas += (f'<polygon points="{pts}" class="{"stablearea" if area.stable else "area"}">'
                      f'<title>{html.escape(area.name)}</title></polygon>')
    north = (f'<g class="north"><line x1="{46 + pw - 14}" y1="{22 + 34}" x2="{46 + pw - 14}" y2="{22 + 12}" '
             f'stroke="#000" stroke-width="2" marker-end="url(#arrow)"/><text x="{46 + pw - 14}" y="{22 + 46}" '
             f'class="xt">N</text></g><defs><marker id="arrow" viewBox="0 0 10 10" refX="5" refY="5" '
             f'markerWidth="5" markerHeight="5" orient="auto"><path d="M0,0 L10,5 L0,10 z"/></marker></defs>')
    ticks_e = "".join(f'<text x="{46 + (x - e0) / (e1 - e0) * pw:.1f}" y="{22 + ph + 13}" class="xt">{_fmt(x)}</text>'
                      for x in _nice_ticks(e0, e1, 4))
    ticks_n = "".join(f'<text x="42" y="{22 + (1 - (y - n0) / (n1 - n0)) * ph + 4:.1f}" class="yt">{_fmt(y)}</text>'
                      for y in _nice_ticks(n0, n1, 5))
    return (f'<svg class="map" viewBox="0 0 {width} {ph + 52}" width="{width}" height="{ph + 52}" role="img" '
            f'aria-label="geocoded displacement"><text x="46" y="14" class="ct">LOS displacement (mm), east/north '
            f'about '
            f'{site.latitude_deg:.4f}, {site.longitude_deg:.4f}</text>'
            f'<image href="{data_uri(rgba)}" x="46" y="22" width="{pw}" height="{ph}" preserveAspectRatio="none"/>'
            f'<rect x="46" y="22" width="{pw}" height="{ph}" class="frame"/>{ticks_e}{ticks_n}{areas}{north}'
            f'<text x="{46 + pw / 2}" y="{ph + 49}" class="xl">east (m)</text>'
            f'<text x="10" y="{22 + ph / 2}" class="yl" transform="rotate(-90 10 {22 + ph / 2})">north (m)</text>'
            f'{_colour_bar(46 + pw + 12, 22, ph, -vmax, vmax, True, "mm")}</svg>')


CSS = """
body{font:14px/1.4 system-ui,sans-serif;margin:0;background:#fafafa;color:#212121}
header{padding:10px 18px;color:#fff;display:flex;gap:24px;align-items:baseline;flex-wrap:wrap}
header h1{font-size:20px;margin:0}main{padding:8px 18px}section{margin:14px 0}
h2{font-size:16px;margin:6px 0;border-bottom:1px solid #ddd}
table{border-collapse:collapse}td,th{padding:3px 8px;border-bottom:1px solid #e0e0e0;text-align:left}
.maps,.charts{display:flex;flex-wrap:wrap;gap:12px}.badge{padding:2px 10px;border-radius:10px;color:#fff}
.ct{font-size:13px;font-weight:600}.xt{font-size:10px;text-anchor:middle}.yt{font-size:10px;text-anchor:end}
.xl,.yl{font-size:11px;text-anchor:middle}.lg{font-size:11px}.cb{font-size:10px}.na{fill:#777}
.frame{fill:none;stroke:#555}.grid{stroke:#e5e5e5}.thr{stroke-dasharray:6 4;stroke-width:1.4}
.area{fill:none;stroke:#ff6f00;stroke-width:2}.stablearea{fill:none;stroke:#1b5e20;stroke-width:2;
stroke-dasharray:4 3}.wp{fill:#fff;stroke:#000;stroke-width:1.5}.wl{font-size:11px;paint-order:stroke;
stroke:#fff;stroke-width:3px}#js-errors{color:#c62828}
"""

SCRIPT = """
(function(){
  var body = document.body, age = document.getElementById('age');
  var updated = Date.parse(body.getAttribute('data-updated'));
  function tick(){ var s = Math.max(0, (Date.now() - updated) / 1000);
    age.textContent = s < 120 ? Math.round(s) + ' s ago' : s < 7200 ? Math.round(s / 60) + ' min ago'
      : Math.round(s / 3600) + ' h ago'; }
  tick(); setInterval(tick, 5000);
  var refresh = Number(body.getAttribute('data-refresh-s'));
  if (refresh > 0) { setTimeout(function(){ location.reload(); }, refresh * 1000); }
  body.setAttribute('data-ready', '1');
})();
"""

ERRORS = """
window.addEventListener('error', function(e){
  var el = document.getElementById('js-errors');
  if (el) { el.textContent += (e.message || 'error') + '\\n'; }
  document.body && document.body.setAttribute('data-js-error', '1');
});
"""


def _cell(v: Any, digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "&ndash;"
    return f"{round(v, digits) + 0.0:.{digits}f}" if isinstance(v, float) else html.escape(str(v))  # no -0.000


def forecast_cell(forecast: dict | None) -> str:
    """The failure forecast of the area table: its time and how far ahead ("in 2.2 h") or, once past,
    how long ago ("0.1 h ago")."""
    if not forecast:
        return "&ndash;"
    h = forecast.get("time_to_failure_h")
    when = ("" if h is None or not math.isfinite(h) else
            f" (in {_cell(float(h), 1)} h)" if h >= 0 else f" ({_cell(float(-h), 1)} h ago)")
    return html.escape(str(forecast["failure_utc"])) + when


def render(cfg: MonitorConfig, static: Static, state: State, title: str, updated_utc: str) -> str:
    """The page's HTML for the committed ``state`` (module docstring)."""
    rec = state.last_record
    last = state.last_accepted_record
    level = last.get("alarm_level", "none")
    shown = state.selected > 0
    n_amp = max(state.n_accepted, 1)
    amp = state.sum_amp / n_amp
    with np.errstate(divide="ignore", invalid="ignore"):
        db = 20 * np.log10(np.where(static.support & (amp > 0), amp, np.nan))
    top = np.nanmax(db) if np.isfinite(db).any() else 0.0
    background = np.where(static.support, np.clip((db - (top - 50)) / 50, 0, 1), np.nan)

    def span(x: np.ndarray) -> float:
        v = np.abs(x[shown & np.isfinite(x)])
        return float(np.percentile(v, 99)) if v.size else 1.0

    dmax, vmax = max(span(state.displacement), 0.05), max(span(state.velocity), 0.05)
    maps = [_map_svg(data_uri(colour_map(state.displacement, shown, background, -dmax, dmax, True)), static, cfg,
                     "cumulative LOS displacement (+ away)", "mm", -dmax, dmax, True),
            _map_svg(data_uri(colour_map(state.velocity, shown, background, -vmax, vmax, True)), static, cfg,
                     f"velocity over the last {cfg.velocity.window_scans} scans", "mm/h", -vmax, vmax, True),
            _map_svg(data_uri(colour_map(state.coherence, static.support, background, 0.0, 1.0, False)), static, cfg,
                     "coherence with the previous scan", "1", 0.0, 1.0, False)]
    geo = _geocoded(static, state.displacement, shown, background, dmax, cfg)
    if geo:
        maps.append(geo)
    ch = state.chart
    charts = []
    names = [w.name for w in cfg.watch] + [a.name for a in cfg.areas]
    colour = {n: SERIES_COLOURS[k % len(SERIES_COLOURS)] for k, n in enumerate(names)}  # one per object
    if cfg.watch:
        charts.append(svg_chart("displacement at the watch points", ch.t,
                                [(w.name, ch.series(f"d:{w.name}"), colour[w.name]) for w in cfg.watch],
                                "LOS displacement (mm)"))
    for a in cfg.areas:
        thr = [(s * t, LEVEL_COLOURS[LEVELS[i + 1]], LEVELS[i + 1]) for i, t in enumerate(a.velocity_mm_per_h or ())
               for s in (1, -1)]
        charts.append(svg_chart(f"area {a.name}: velocity (median of its points)", ch.t,
                                [(a.name, ch.series(f"v:{a.name}"), colour[a.name])], "mm/h", thr))
    if cfg.areas:
        charts.append(svg_chart("area displacement (median of its points)", ch.t,
                                [(a.name, ch.series(f"d:{a.name}"), colour[a.name]) for a in cfg.areas], "mm"))
    charts.append(svg_chart("stable points: RMS displacement", ch.t,
                            [("after APS", ch.series("aps_residual_mm")),
                             ("without APS", ch.series("raw_stable_rms_mm"))], "mm"))
    charts.append(svg_chart("median coherence of the points", ch.t, [("coherence", ch.series("coherence_median"))],
                            "1"))
    met = ch.series("meteo_refractivity_ppm")
    met = met - met[np.isfinite(met)][0] if np.isfinite(met).any() else met
    charts.append(svg_chart("refractivity change since the first scan: APS range term vs meteo", ch.t,
                            [("APS", ch.series("aps_refractivity_ppm")), ("meteo", met)], "ppm"))
    area_rows = "".join(
        f"<tr><td>{html.escape(name)}</td><td><span class='badge' style='background:{LEVEL_COLOURS[a['level']]}'>"
        f"{a['level']}</span></td><td>{a.get('n_points', 0)}</td><td>{_cell(a.get('displacement_mm'))}</td>"
        f"<td>{_cell(a.get('velocity_mm_per_h'))}</td><td>{_cell(a.get('acceleration_mm_per_h2'))}</td>"
        f"<td>{forecast_cell(a.get('forecast'))}</td></tr>"
        for name, a in last.get("areas", {}).items())
    watch_rows = "".join(f"<tr><td>{html.escape(k)}</td><td>{_cell(v)}</td>"
                         f"<td>{_cell(last.get('velocity_mm_per_h', {}).get(k))}</td></tr>"
                         for k, v in last.get("displacement_mm", {}).items())
    events = "".join(
        f"<tr><td>{html.escape(str(e['time_utc']))}</td><td>{e['scan']}</td><td>{html.escape(e['area'])}</td>"
        f"<td>{e['event']}</td><td><span class='badge' style='background:{LEVEL_COLOURS[e['level']]}'>{e['level']}"
        f"</span></td><td>{html.escape(e['trigger'])} {_cell(e.get('value'))}</td>"
        f"<td>{html.escape(str(e.get('forecast_failure_utc') or ''))}</td></tr>"
        for e in reversed(state.recent_events)) or "<tr><td colspan='7'>no alarm so far</td></tr>"
    health = [("last scan", f"{rec.get('scan')} at {rec.get('time_utc')} ({rec.get('status')})"),
              ("last accepted scan", f"{last.get('scan')} at {last.get('time_utc')}"),
              ("scans accepted / rejected / failed", f"{state.n_accepted} / {state.n_rejected} / {state.n_failed}"),
              ("last problem", rec.get("reason") or "none"),
              ("points measured / stable", f"{last.get('n_points', 0)} / {last.get('n_stable', 0)}"),
              ("APS residual on stable points", f"{_cell(last.get('aps_residual_mm'))} mm (without APS "
                                                f"{_cell(last.get('raw_stable_rms_mm'))} mm)"),
              ("page written", updated_utc)]
    health_rows = "".join(f"<tr><th>{html.escape(k)}</th><td>{html.escape(str(v))}</td></tr>" for k, v in health)
    record = html.escape(json.dumps(rec, indent=1, default=str))
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width,initial-scale=1">
<title>{html.escape(title)}: scan {rec.get('scan')} ({level})</title><style>{CSS}</style>
<script>{ERRORS}</script></head>
<body data-updated="{updated_utc}" data-refresh-s="{cfg.page.refresh_s:g}" data-latest-scan="{rec.get('scan')}">
<header style="background:{LEVEL_COLOURS[level]}"><h1>{html.escape(title)}</h1>
<span>scan <b id="latest-scan">{rec.get('scan')}</b> &middot; <span id="latest-time">{rec.get('time_utc')}</span>
&middot; {rec.get('status')}</span><span>alarm level: <b id="alarm-level">{level}</b></span>
<span>updated <span id="age">{updated_utc}</span></span></header>
<main><pre id="js-errors"></pre>
<section><h2>Instrument and processing</h2><table>{health_rows}</table></section>
<section><h2>Areas</h2><table><tr><th>area</th><th>level</th><th>points</th><th>displacement (mm)</th>
<th>velocity (mm/h)</th><th>acceleration (mm/h&sup2;)</th><th>failure forecast (inverse velocity)</th></tr>
{area_rows}</table></section>
<section><h2>Watch points</h2><table><tr><th>point</th><th>displacement (mm)</th><th>velocity (mm/h)</th></tr>
{watch_rows}</table></section>
<section><h2>Latest maps (scan {last.get('scan')}, {last.get('time_utc')})</h2><div class="maps">{''.join(maps)}</div>
</section><section><h2>Time series</h2><div class="charts">{''.join(charts)}</div></section>
<section><h2>Alarms (latest first; all of them in alarms.csv)</h2><table><tr><th>time (UTC)</th><th>scan</th>
<th>area</th><th>event</th><th>level</th><th>trigger</th><th>failure forecast</th></tr>{events}</table></section>
<section><details><summary>latest scan record</summary><pre>{record}</pre></details></section>
</main><script>{SCRIPT}</script></body></html>
"""

