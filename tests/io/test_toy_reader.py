"""The sensor-reader recipe (docs/ingest.md, "A new sensor reader"), end to end: a toy format defined in
this one file, registered with ``READERS.register``, found by sniffing by ``sarcli ingest`` and
``sarcli info``; its options parsed from ``--option KEY=VALUE``; several data sets in one input written
one product each. Expected values come from the arrays written into the toy files here (numpy)."""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np
import pytest

from sarcli.config import to_mapping
from sarcli.errors import ConfigError, FormatError
from sarcli.io.h5common import sha256_file
from sarcli.io.raw import read_raw
from sarcli.io.readers import READERS, Ingested
from sarcli.model.raw import Radar, RawProduct

MAGIC = b"TOYSAR1\n"
C = 299_792_458.0


# ---- the reader: the whole plug-in is this section ----------------------------------------------------


@dataclass(frozen=True)
class ToyOptions:
    """scale: factor applied to the samples; epoch: UTC time of the first line."""

    scale: float = 1.0
    epoch: str = "2020-01-01T00:00:00.000000Z"

    def __post_init__(self) -> None:
        if not self.scale > 0:
            raise ConfigError(f"scale must be positive, got {self.scale}")


class ToyReader:
    name = "toy"
    description = "toy format of the reader-recipe test: TOYSAR1 header line, JSON line, complex64 samples"
    Options = ToyOptions

    def sniff(self, sources: Sequence[Path]) -> bool:
        if len(sources) != 1 or not Path(sources[0]).is_file():
            return False
        with open(sources[0], "rb") as f:
            return f.read(len(MAGIC)) == MAGIC

    def read(self, sources: Sequence[Path], options: ToyOptions) -> Ingested:
        path = Path(sources[0])
        with open(path, "rb") as f:
            f.readline()
            try:
                head = json.loads(f.readline())
            except json.JSONDecodeError:
                raise FormatError(f"{path}: toy header is not JSON") from None
            data = np.fromfile(f, dtype=np.complex64)
        n, m, names = head["n_lines"], head["n_samples"], head["channels"]
        if data.size != n * m * len(names):
            raise FormatError(f"{path}: {data.size} samples, the header says {n * m * len(names)}")
        cubes = data.reshape(len(names), n, m) * np.float32(options.scale)
        radar = Radar(carrier_frequency_hz=5.3e9, wavelength_m=C / 5.3e9, prf_hz=head["prf_hz"],
                      range_sampling_rate_hz=20e6, chirp_rate_hz_per_s=4e11, pulse_length_s=10e-6,
                      window_start_s=6e-3, first_range_m=C * 6e-3 / 2)
        products = {(name if len(names) > 1 else ""): RawProduct(
            echo=cube, azimuth_time=np.arange(n) / head["prf_hz"], epoch_utc=options.epoch, radar=radar,
            source="toy") for name, cube in zip(names, cubes, strict=True)}
        return Ingested(products, (path,), {"format": self.name, **to_mapping(options)},
                        [f"{len(names)} channel(s)"], {k: {"toy_channel": k or names[0]} for k in products})


# ---- the tests ------------------------------------------------------------------------------------------


@pytest.fixture
def toy():
    READERS.register("toy", ToyReader())
    yield
    READERS.unregister("toy")


def write_toy(path: Path, cubes: np.ndarray, names: list[str], prf: float = 1000.0) -> Path:
    with open(path, "wb") as f:
        f.write(MAGIC)
        f.write(json.dumps({"n_lines": cubes.shape[1], "n_samples": cubes.shape[2], "channels": names,
                            "prf_hz": prf}).encode() + b"\n")
        f.write(np.ascontiguousarray(cubes, np.complex64).tobytes())
    return path


def _cubes(k: int, n: int = 6, m: int = 8, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return (rng.standard_normal((k, n, m)) + 1j * rng.standard_normal((k, n, m))).astype(np.complex64)


def test_ingest_finds_the_toy_reader_by_sniffing(cli, toy, tmp_path):
    cubes = _cubes(1)
    src = write_toy(tmp_path / "scene.toy", cubes, ["HH"])
    before = sha256_file(src)
    r = cli("ingest", src, "-o", tmp_path / "raw.h5", "--option", "scale=2", "--json")
    assert r.exit_code == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["format"] == "toy" and s["shape"] == [6, 8] and s["toy_channel"] == "HH" and s["notes"] == ["1 channel(s)"]
    p = read_raw(tmp_path / "raw.h5")
    assert np.array_equal(p.echo, cubes[0] * np.float32(2.0)) and p.source == "toy"
    assert np.allclose(p.azimuth_time, np.arange(6) / 1000.0, rtol=0, atol=1e-15)
    with h5py.File(tmp_path / "raw.h5") as f:
        params = json.loads(f.attrs["parameters"])
        assert params["format"] == "toy" and params["scale"] == 2.0 and params["workflow"] == "ingest"
        assert json.loads(f.attrs["inputs"])[0]["sha256"] == before
    assert sha256_file(src) == before


def test_info_describes_the_toy_input_without_writing(cli, toy, tmp_path):
    src = write_toy(tmp_path / "scene.toy", _cubes(1), ["VV"], prf=500.0)
    r = cli("info", src, "--json")
    assert r.exit_code == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["product_type"] == "raw input" and s["format"] == "toy" and s["shape"] == [6, 8]
    assert s["prf_hz"] == 500.0 and s["azimuth_span_s"] == pytest.approx(5 / 500.0, rel=1e-12)
    assert s["last_range_m"] == pytest.approx(C * 6e-3 / 2 + 7 * C / (2 * 20e6), rel=1e-15)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.toy"]
    human = cli("info", src).stdout
    assert "raw input (toy)" in human and "orbit: none" in human


@pytest.mark.parametrize("output, expected", [
    ("out", ["out/A.h5", "out/B_2.h5"]),              # a folder: NAME.h5 each (names made file-safe)
    ("raw.h5", ["raw_A.h5", "raw_B_2.h5"]),           # a .h5 name: STEM_NAME.h5 next to it
])
def test_several_data_sets_are_one_product_each(cli, toy, tmp_path, output, expected):
    cubes = _cubes(2, seed=3)
    src = write_toy(tmp_path / "two.toy", cubes, ["A", "B/2"])
    r = cli("ingest", src, "-o", tmp_path / output, "--json")
    assert r.exit_code == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["outputs"] == [str(tmp_path / e) for e in expected] and [p["name"] for p in s["products"]] == ["A", "B/2"]
    for k, e in enumerate(expected):
        assert np.array_equal(read_raw(tmp_path / e).echo, cubes[k])
        with h5py.File(tmp_path / e) as f:
            assert json.loads(f.attrs["parameters"])["product"] == ["A", "B/2"][k]
    info = json.loads(cli("info", src, "--json").stdout)
    assert [p["name"] for p in info["products"]] == ["A", "B/2"] and info["format"] == "toy"


def test_toy_options_and_format_errors_are_one_line(cli, toy, tmp_path):
    src = write_toy(tmp_path / "scene.toy", _cubes(1), ["HH"])
    for args, needle in [
        (("--option", "scale=-1"), "scale must be positive"),
        (("--option", "colour=red"), "toy options: unknown option(s) colour; known: epoch, scale"),
        (("--option", "scale"), "--option 'scale': expected KEY=VALUE"),
        (("--missing", "zero"), "toy options: unknown option(s) missing"),
        (("--format", "nope"), "unknown sensor reader 'nope'; known: ceos-rs1, matlab-cw, "),
    ]:
        r = cli("ingest", src, "-o", tmp_path / "x.h5", *args)
        lines = r.stderr.strip().splitlines()
        assert r.exit_code == 2 and len(lines) == 1 and needle in lines[0], (args, r.stderr)
    assert not (tmp_path / "x.h5").exists()
    (tmp_path / "junk.toy").write_bytes(MAGIC + b"{not json\n")
    r = cli("ingest", tmp_path / "junk.toy", "-o", tmp_path / "x.h5")
    assert r.exit_code == 1 and "toy header is not JSON" in r.stderr


def test_unrecognised_input_is_one_line_naming_the_formats(cli, toy, tmp_path):
    (tmp_path / "x.bin").write_bytes(b"\0" * 64)
    r = cli("ingest", tmp_path / "x.bin", "-o", tmp_path / "x.h5")
    assert r.exit_code == 1 and "no reader recognises this input (known formats: ceos-rs1, matlab-cw, " in r.stderr
    assert ", toy)" in r.stderr
    r = cli("info", tmp_path / "x.bin")
    assert r.exit_code == 1 and "not a sarcli product, a GeoTIFF, or a raw input" in r.stderr
