"""Emulated AOD/CCD processor vs the digital RD focus of the same scene: time, and cost per limitation.

Scene: samples/aod_ccd_scene.toml (1536 x 480 raw samples). Each figure is the best of 3 runs after a
warm-up (numba/FFT plans); the first-call time of the RD focus is reported separately.
"""

from __future__ import annotations

from pathlib import Path

from bench.common import best_time, first_call_time, markdown_table, peak_rss_bytes, write_results

SCENE = Path(__file__).resolve().parents[1] / "samples" / "aod_ccd_scene.toml"


def main() -> None:
    from sarcli.design.params import doppler_bandwidth
    from sarcli.focus.rda import focus_rd
    from sarcli.model.doppler import GeometricDoppler
    from sarcli.optical import limitations as lim
    from sarcli.optical.devices import CCD, OpticalSettings
    from sarcli.optical.emulator import emulate
    from sarcli.sim.scene import load_scene
    from sarcli.sim.stripmap import simulate

    raw = simulate(load_scene(SCENE))
    dop = GeometricDoppler(250.0, 0.0, raw.radar.wavelength_m)
    bw = doppler_bandwidth(raw.echo, raw.radar.prf_hz)

    def rd():
        return focus_rd(raw, dop, azimuth_bandwidth_hz=bw)

    rd_first = first_call_time(rd)
    t_rd = best_time(rd, repeat=3, warmup=0)
    rows = [["digital RD", f"{t_rd:.3f}", "1.00", "-"]]
    data = {"rd_first_call_s": rd_first, "rd_s": t_rd, "shape": list(raw.echo.shape), "cases": {}}
    cases = [("ideal (no limitation)", "")] + [(f"+{n} (with ccd_size)", f"ccd_size,{n}") for n in lim.ALL
                                               if n != "ccd_size"] + [("ccd_size", "ccd_size"), ("all", "all")]
    for label, names in cases:
        t = best_time(lambda names=names: emulate(raw, names, OpticalSettings(), centre_range_m=10000.0),
                      repeat=3, warmup=1)
        rows.append([f"optical {label}", f"{t:.3f}", f"{t / t_rd:.2f}", names or "none"])
        data["cases"][label] = t
    scaling = []
    for n_rows in (123, 245, 491):
        s = OpticalSettings(ccd=CCD(rows=n_rows))
        t = best_time(lambda s=s: emulate(raw, "all", s, centre_range_m=10000.0), repeat=3, warmup=1)
        scaling.append([n_rows, f"{t:.3f}"])
        data.setdefault("rows_scaling", {})[n_rows] = t
    data["peak_rss_bytes"] = peak_rss_bytes()
    md = ("# Optical (AOD/CCD) emulation vs digital RD\n\n"
          f"Scene {SCENE.name}, raw {raw.echo.shape[0]} x {raw.echo.shape[1]}; RD first call "
          f"(compilation) {rd_first:.2f} s, then best of 3.\n\n"
          + markdown_table(["processor", "seconds", "x RD", "limitations"], rows)
          + "\nCCD rows (all limitations) vs time:\n\n" + markdown_table(["CCD rows", "seconds"], scaling)
          + f"\nPeak RSS of the benchmark process: {data['peak_rss_bytes'] / 2**20:.0f} MiB\n")
    write_results("bench_optical", md, data)


if __name__ == "__main__":
    main()
