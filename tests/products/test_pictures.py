"""Pictures people read: the Doppler plot (no degenerate azimuth panel, the truth on its ranges), the
quality impulse-response PNG, hue/brightness phase pictures, the quicklook's time-axis note against the
simulator's beam-centre and zero-Doppler times."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from sarcli.io.images import phase_rgb


def _png_size(path) -> tuple[int, int]:
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])  # width, height of the IHDR chunk


def test_phase_rgb_hue_and_brightness():
    ph = np.array([[0.0, np.pi, -np.pi / 2, 0.0, np.nan]])
    br = np.array([[1.0, 1.0, 1.0, 0.0, 1.0]])
    rgba = phase_rgb(ph, br)
    # hsv with hue (phi + pi) / 2 pi: 0 -> hue 1/2 (cyan), pi -> hue 0 (red), -pi/2 -> hue 1/4 (yellow-green)
    np.testing.assert_allclose(rgba[0, 0, :3], [0.0, 1.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(rgba[0, 1, :3], [1.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(rgba[0, 2, :3], [0.5, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(rgba[0, 3, :3], [0.0, 0.0, 0.0], atol=1e-12)  # no coherence: black
    assert rgba[0, 4, 3] == 0.0 and np.all(rgba[0, :4, 3] == 1.0)  # no data: transparent


@pytest.mark.slow
def test_doppler_plot_three_range_panels_for_one_azimuth_block(cli, small, tmp_path):
    from sarcli.doppler.plot import truth_curves
    from sarcli.io.doppler_product import read_doppler
    from sarcli.io.raw import read_raw

    png, d = tmp_path / "d.png", tmp_path / "d.h5"
    r = cli("doppler", small.raw, "-o", d, "--plot", png)
    assert r.exit_code == 0, r.stderr
    assert read_doppler(d).summary.n_az_blocks == 1
    assert _png_size(png) == (1000, 960)  # 3 panels of 3.2 in at 100 dpi: no azimuth-time panel
    raw = read_raw(small.raw, load_echo=False)
    t = truth_curves(raw)
    c, rad = 299792458.0, raw.radar
    np.testing.assert_allclose(t["range_m"][[0, -1]], c / 2 * (rad.window_start_s + np.array([0, 599])
                                                             / rad.range_sampling_rate_hz))
    assert t["fdc_hz"].shape == (600,)


@pytest.mark.slow
def test_quality_plot_and_time_axis_note(cli, small, tmp_path):
    from sarcli.focus.quicklook import time_axis_label
    from sarcli.io.slc import read_slc

    png = tmp_path / "irf.png"
    r = cli("quality", small.slc, "--plot", png)
    assert r.exit_code == 0, r.stderr
    assert _png_size(png) == (1400, 800)  # one row of 4 in per target, two targets
    slc = read_slc(small.slc, load_image=False)
    tg = slc.truth["targets"]
    lead = float(np.mean(tg["beam_center_time_s"] - tg["zero_doppler_time_s"]))  # the simulator's own times
    label = time_axis_label(slc)
    shown = float(label.split("this ")[1].split(" s")[0])
    assert label.startswith("zero-Doppler time (UTC, ") and shown == pytest.approx(lead, abs=0.05)
    assert lead > 3.0  # RADARSAT-1's squint: the -3.7 s of the issue


def _drawn(monkeypatch, draw):
    """The matplotlib figure ``draw()`` saves (captured at savefig, drawn so its tick labels exist)."""
    from matplotlib.figure import Figure

    figs = []
    real = Figure.savefig

    def keep(self, *a, **k):
        self.canvas.draw()
        figs.append(self)
        return real(self, *a, **k)

    monkeypatch.setattr(Figure, "savefig", keep)
    draw()
    return figs[-1]


def test_quicklook_time_axis_in_utc_and_partly_focused_lines_marked(small, tmp_path, monkeypatch):
    """The time axis reads UTC clock times (no '+9.268e3' offset), labelled with the date; the lines
    without their whole aperture are shaded and named in the legend; an SLC without a fully focused line
    says so in the title."""
    import dataclasses
    import datetime as dt

    from sarcli.focus.quicklook import write_slc_quicklook
    from sarcli.io.slc import read_slc

    slc = read_slc(small.slc)
    fig = _drawn(monkeypatch, lambda: write_slc_quicklook(tmp_path / "q.png", slc, 2, 1))
    ax = fig.axes[0]
    epoch = dt.datetime.fromisoformat(slc.epoch_utc.replace("Z", "+00:00"))
    labels = [t.get_text() for t in ax.get_yticklabels() if t.get_text()]
    assert labels and ax.yaxis.get_offset_text().get_text() == ""
    for t, text in zip(ax.get_yticks(), [t.get_text() for t in ax.get_yticklabels()], strict=True):
        if text:
            assert text == (epoch + dt.timedelta(seconds=float(t))).strftime("%H:%M:%S.%f")[:11]
    assert "UTC" in ax.get_ylabel() and epoch.strftime("%Y-%m-%d") in ax.get_ylabel()
    n = slc.azimuth_time.size
    partly = slc.first_full_line > 0 or slc.last_full_line < n - 1
    legend = ax.get_legend()
    assert partly and legend is not None and "partly focused" in legend.get_texts()[0].get_text()
    none = dataclasses.replace(slc, first_full_line=n, last_full_line=-1)
    fig = _drawn(monkeypatch, lambda: write_slc_quicklook(tmp_path / "none.png", none, 2, 1))
    assert "no fully focused line" in fig.axes[0].get_title()


@pytest.mark.slow
def test_quality_plot_titles_inside_the_picture(cli, small, tmp_path, monkeypatch):
    """Every panel title of the impulse-response picture stays over its own column: right of the panel on
    its left and inside the figure with a margin (the one-line title reached the right edge)."""
    fig = _drawn(monkeypatch, lambda: cli("quality", small.slc, "--plot", tmp_path / "irf.png"))
    width = fig.bbox.width
    boxes = [ax.get_window_extent() for ax in fig.axes]
    checked = 0
    for ax, own in zip(fig.axes, boxes, strict=True):
        if not ax.get_title():
            continue
        box = ax.title.get_window_extent()
        left = max([b.x1 for b in boxes if b.x1 <= own.x0 + 1 and b.y0 < own.y1 and b.y1 > own.y0], default=0.0)
        assert left <= box.x0 and box.x1 <= width - 10, (ax.get_title(), box.x0, box.x1, left, width)
        checked += 1
    assert checked >= 6  # three panels per target, two targets


@pytest.mark.slow
def test_doppler_plot_without_an_orbit_lists_only_what_it_draws(cli, small, tmp_path, monkeypatch):
    """A raw product without an orbit: no 'orbit + attitude geometry' or 'geometric seed' entries (they
    would have no line); every legend entry of every panel has finite data."""
    import shutil

    import h5py

    raw = tmp_path / "bare.h5"
    shutil.copy(small.raw, raw)
    with h5py.File(raw, "r+") as f:
        for name in ("orbit", "orbit_ecef", "attitude"):
            if name in f:
                del f[name]
    fig = _drawn(monkeypatch, lambda: cli("doppler", raw, "--plot", tmp_path / "d.png"))
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is None:
            continue
        labels = [t.get_text() for t in legend.get_texts()]
        assert not any("geometr" in x or "orbit" in x for x in labels), labels
        for line in ax.get_lines():
            if not line.get_label().startswith("_"):
                assert np.isfinite(np.asarray(line.get_ydata(), float)).any(), line.get_label()
