"""Product storage: sizes and costs of the raw echo's HDF5 compression, echo chunking for line-block
reads, SLC compression, the Cloud-Optimized GeoTIFF writer against a plain tiled GeoTIFF, and the GeoTIFF
compressions on a full scene's map.

Data: the real RADARSAT-1 Vancouver raw block (``../shared/data/rs1_vancouver_block1.mat``, 1536 lines x
2048 samples of 4-bit levels, read by sarcli's MATLAB reader), a float echo of complex Gaussian noise of
the same shape (an unquantized simulation: nothing to compress), and the SLC of the product tests' scene
(tests/products/scenes/small.toml, focused here). Page cache warm, best of 3, one process.

- ``write_raw``: the whole product (echo + metadata) with each echo compression;
- ``read all``: ``read_raw`` (the echo into memory);
- ``read blocks``: ``read_raw_echo_block`` over the file in 64-line blocks (the streaming focuser's
  pattern), with sarcli's whole-line chunks and with the former 256 x 2048 chunks;
- sizes are the echo's storage in the file (HDF5 ``get_storage_size``) and the whole file.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

from bench.common import SARCLI, SHARED, best_time, markdown_table, tiled_real_block, write_results

BLOCK = 64
REPO = Path(__file__).resolve().parents[1]


def _rs1():
    from sarcli.io.matlab import read_matlab_block

    return read_matlab_block(SHARED / "rs1_vancouver_block1.mat", SHARED / "rs1_vancouver_run_params.mat")


def _float_twin(p):
    import dataclasses

    rng = np.random.default_rng(0)
    e = (rng.normal(size=p.echo.shape) + 1j * rng.normal(size=p.echo.shape)).astype(np.complex64)
    return dataclasses.replace(p, echo=e)


def _read_blocks(path: Path) -> None:
    from sarcli.io.raw import raw_shape, read_raw_echo_block

    n, _ = raw_shape(path)
    for a in range(0, n, BLOCK):
        read_raw_echo_block(path, a, min(n, a + BLOCK))


def raw_rows(name: str, p, folder: Path) -> list[dict]:
    from sarcli.io.raw import echo_compression, read_raw, write_raw

    out = []
    for mode in ("none", "gzip", "lzf", "auto"):
        path = folder / f"{name}_{mode}.h5"
        t_w = best_time(lambda path=path, mode=mode: write_raw(path, p, compression=mode), repeat=3, warmup=0)
        with h5py.File(path) as f:
            echo_bytes = f["echo"].id.get_storage_size()
            chunks = f["echo"].chunks
        out.append({"data": name, "compression": mode, "chosen": echo_compression(p.echo, mode) or "none",
                    "echo_MB": echo_bytes / 1e6, "file_MB": path.stat().st_size / 1e6,
                    "ratio": echo_bytes / p.echo.nbytes, "write_s": t_w,
                    "read_all_s": best_time(lambda path=path: read_raw(path)),
                    "read_blocks_s": best_time(lambda path=path: _read_blocks(path)), "chunks": list(chunks)})
    # gzip level 4 (the h5py helper's default) and without the shuffle, for the record
    e = np.asarray(p.echo, np.complex64)
    for label, kw in (("gzip-4 + shuffle", {"compression": "gzip", "compression_opts": 4, "shuffle": True}),
                      ("gzip-1, no shuffle", {"compression": "gzip", "compression_opts": 1, "shuffle": False}),
                      ("gzip-1 + shuffle, 256 x 2048 chunks", {"compression": "gzip", "compression_opts": 1,
                                                              "shuffle": True, "chunks": (256, 2048)})):
        path = folder / f"{name}_{label.replace(' ', '_').replace(',', '')}.h5"

        def write(path=path, kw=kw):
            with h5py.File(path, "w") as f:
                f.create_dataset("echo", data=e, **{"chunks": (128, e.shape[1]), **kw})

        t_w = best_time(write, repeat=3, warmup=0)

        def blocks(path=path):
            with h5py.File(path) as f:
                ds = f["echo"]
                for a in range(0, ds.shape[0], BLOCK):
                    ds[a:a + BLOCK]

        with h5py.File(path) as f:
            size = f["echo"].id.get_storage_size()
        out.append({"data": name, "compression": label, "chosen": label, "echo_MB": size / 1e6,
                    "file_MB": path.stat().st_size / 1e6, "ratio": size / e.nbytes, "write_s": t_w,
                    "read_all_s": best_time(lambda path=path: h5py.File(path)["echo"][()]),
                    "read_blocks_s": best_time(blocks), "chunks": list(kw.get("chunks", (128, e.shape[1])))})
    return out


def slc_rows(folder: Path) -> list[dict]:
    from sarcli.io.slc import read_slc
    from tests.conftest import run_cli

    scene = Path(__file__).resolve().parents[1] / "tests" / "products" / "scenes" / "small.toml"
    raw, slc = folder / "s_raw.h5", folder / "s_slc.h5"
    assert run_cli("simulate", scene, "-o", raw).exit_code == 0
    assert run_cli("focus", raw, "-o", slc).exit_code == 0
    img = read_slc(slc).image
    out = []
    for label, kw in (("none", {}), ("gzip-1 + shuffle", {"compression": "gzip", "compression_opts": 1,
                                                          "shuffle": True}),
                      ("lzf + shuffle", {"compression": "lzf", "shuffle": True})):
        path = folder / f"slc_{label.split()[0]}.h5"

        def write(path=path, kw=kw):
            with h5py.File(path, "w") as f:
                f.create_dataset("image", data=img, chunks=(min(256, img.shape[0]), img.shape[1]), **kw)

        t_w = best_time(write, repeat=3, warmup=0)
        with h5py.File(path) as f:
            size = f["image"].id.get_storage_size()
        out.append({"compression": label, "MB": size / 1e6, "ratio": size / img.nbytes, "write_s": t_w,
                    "read_s": best_time(lambda path=path: h5py.File(path)["image"][()])})
    return out


def geotiff_rows(folder: Path) -> list[dict]:
    import rasterio
    from rasterio.transform import Affine

    from sarcli.io.images import Band, write_geotiff

    rng = np.random.default_rng(2)
    amp = np.abs(rng.normal(size=(2048, 2048)) + 1j * rng.normal(size=(2048, 2048))).astype(np.float32)
    db = (20 * np.log10(amp)).astype(np.float32)
    tr = Affine(10, 0, 5e5, 0, -10, 4e6)

    def cog():
        write_geotiff(folder / "cog.tif", [Band(amp, "a", "1", "power"), Band(db, "db", "dB", "power_db")],
                      "EPSG:32610", transform=tr)

    def plain():
        with rasterio.open(folder / "plain.tif", "w", driver="GTiff", width=2048, height=2048, count=2,
                           dtype="float32", crs="EPSG:32610", transform=tr, tiled=True, blockxsize=256,
                           blockysize=256, compress="deflate", predictor=3) as d:
            d.write(np.stack([amp, db]))
            d.build_overviews([2, 4, 8], rasterio.enums.Resampling.average)

    rows = []
    for label, fn, name in (("COG, power overviews (sarcli)", cog, "cog.tif"),
                            ("GTiff tiled + averaged overviews", plain, "plain.tif")):
        t = best_time(fn, repeat=3, warmup=0)
        rows.append({"writer": label, "write_s": t, "MB": (folder / name).stat().st_size / 1e6})
    return rows


#: the Vancouver block's Doppler (docs/doppler.md, section F), for focusing its tiled full scene
VANCOUVER_FDC_FR = ("-6900", "-1733")


def full_scene_map_rows(folder: Path) -> tuple[list[dict], dict]:
    """The map GeoTIFF of a full scene (the real block tiled to 23000 x 6354 on the orbit of
    samples/rs1_point.toml, focused by ``sarcli focus --geotiff --geotiff-compression none``), copied by
    GDAL's COG driver with each compression as write_geotiff does (its levels kept): the copy's time, the
    fsync that makes it durable, and the file size."""
    import json
    import os
    import subprocess

    import rasterio
    import rasterio.shutil

    from sarcli import threads
    from sarcli.io.images import BLOCK as TILE
    from sarcli.io.images import COMPRESSIONS

    raw, sample = folder / "full.h5", folder / "sample.h5"
    subprocess.run([SARCLI, "-q", "simulate", str(REPO / "samples" / "rs1_point.toml"), "-o", str(sample)], check=True)
    gib = tiled_real_block(raw, orbit_of=sample)
    first = folder / "map_focus.tif"
    fdc, fr = VANCOUVER_FDC_FR
    report = json.loads(subprocess.run(
        [SARCLI, "-q", "focus", str(raw), "-o", str(folder / "full_slc.h5"), "--fdc", fdc, "--fr", fr, "--geotiff",
         str(first), "--geotiff-compression", "none", "--json"], check=True, capture_output=True, text=True).stdout)
    raw.unlink()
    (folder / "full_slc.h5").unlink()
    with rasterio.open(first) as d:
        shape = [d.height, d.width]
        nan = float(np.mean(np.isnan(d.read(1, out_shape=(d.height // 8, d.width // 8)))))
    rows = []
    for name, codec in COMPRESSIONS.items():
        path = folder / f"map_{name}.tif"
        t0 = time.perf_counter()
        rasterio.shutil.copy(str(first), str(path), driver="COG", **codec, BLOCKSIZE=str(TILE),
                             OVERVIEWS="FORCE_USE_EXISTING", BIGTIFF="IF_SAFER", NUM_THREADS=str(threads.budget()))
        t1 = time.perf_counter()
        fd = os.open(path, os.O_RDONLY)
        os.fsync(fd)
        os.close(fd)
        t2 = time.perf_counter()
        rows.append({"compression": name, "copy_s": t1 - t0, "fsync_s": t2 - t1, "total_s": t2 - t0,
                     "MB": path.stat().st_size / 1e6})
        path.unlink()
    info = {"echo_gib": gib, "map_shape": shape, "nan_fraction": nan, "focus_total_s": report["timings_s"]["total_s"],
            "products_s": report["timings_s"]["statistics_and_products_s"]}
    return rows, info


def main() -> None:
    if not (SHARED / "rs1_vancouver_block1.mat").is_file():
        raise SystemExit(f"bench_products needs {SHARED / 'rs1_vancouver_block1.mat'} (../shared/data)")
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as td:
        folder = Path(td)
        rs1 = _rs1()
        raw = raw_rows("RS-1 4-bit block", rs1, folder) + raw_rows("float noise echo", _float_twin(rs1), folder)
        slc = slc_rows(folder)
        tif = geotiff_rows(folder)
        full, full_info = full_scene_map_rows(folder)
    md = ["# bench_products: product storage\n",
          f"Raw echo: {rs1.echo.shape[0]} x {rs1.echo.shape[1]} complex64 "
          f"({rs1.echo.nbytes / 1e6:.1f} MB in memory); read blocks = {BLOCK}-line blocks over the file.\n",
          markdown_table(["data", "compression", "chosen", "echo MB", "file MB", "ratio", "write s", "read all s",
                          f"read {BLOCK}-line blocks s", "chunks"],
                         [[r["data"], r["compression"], r["chosen"], r["echo_MB"], r["file_MB"], r["ratio"],
                           r["write_s"], r["read_all_s"], r["read_blocks_s"], "x".join(map(str, r["chunks"]))]
                          for r in raw]),
          "\nSLC image (tests/products/scenes/small.toml focused, complex64):\n",
          markdown_table(["compression", "MB", "ratio", "write s", "read s"],
                         [[r["compression"], r["MB"], r["ratio"], r["write_s"], r["read_s"]] for r in slc]),
          "\nGeoTIFF, 2 bands float32 2048 x 2048 (amplitude and dB of speckle):\n",
          markdown_table(["writer", "write s", "MB"], [[r["writer"], r["write_s"], r["MB"]] for r in tif]),
          f"\nMap GeoTIFF of a full scene (the real block tiled to 23000 x 6354, {full_info['echo_gib']:.2f} GiB of "
          f"echo, on the orbit of samples/rs1_point.toml; map {full_info['map_shape'][0]} x "
          f"{full_info['map_shape'][1]}, 2 bands float32, {100 * full_info['nan_fraction']:.0f} % no-data corners): "
          "GDAL's COG copy with each compression (what write_geotiff runs last, overviews kept) and the fsync "
          f"that makes the file durable; one run each. The whole `sarcli focus --geotiff` took "
          f"{full_info['focus_total_s']:.1f} s, its statistics and products {full_info['products_s']:.1f} s "
          "(uncompressed).\n",
          markdown_table(["compression", "COG copy s", "fsync s", "total s", "x deflate", "MB", "x deflate size"],
                         [[r["compression"], r["copy_s"], r["fsync_s"], r["total_s"], r["total_s"] / full[0]["total_s"],
                           r["MB"], r["MB"] / full[0]["MB"]] for r in full]),
          f"\nTotal {time.perf_counter() - t0:.0f} s.\n"]
    write_results("bench_products", "\n".join(md), {"raw": raw, "slc": slc, "geotiff": tif,
                                                     "full_scene_map": {"rows": full, **full_info}})


if __name__ == "__main__":
    main()
