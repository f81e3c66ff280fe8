"""A new focuser is one file plus one registration (docs/extending.md, "A new focuser").

The toy focuser below scales the raw lines by ``gain`` (no focusing at all: its output is checked
exactly against the input). Registered with ``FOCUSERS.register``, it runs through
``sarcli focus --algorithm toy`` with its option from ``--set``, streamed in blocks from HDF5,
written as an SLC product by the generic workflow.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np
import pytest

from sarcli.focus import FOCUSERS
from sarcli.model.slc import SLC, DopplerUsed


@dataclass(frozen=True)
class ToyOptions:
    gain: float = 1.0
    block_lines: int = 64


@dataclass
class ToyPlan:
    raw: object
    options: ToyOptions
    output_shape: tuple[int, int]
    n_blocks: int

    def block_rows(self, b: int) -> tuple[int, int]:
        s = b * self.options.block_lines
        return s, min(s + self.options.block_lines, self.output_shape[0])


class Toy:
    name = "toy"
    Options = ToyOptions
    streams = True
    needs_doppler = False

    def plan(self, raw, shape, doppler, options, terrain):
        return ToyPlan(raw, options, tuple(shape), -(-shape[0] // options.block_lines))

    def focus_block(self, plan, b, read_lines):
        s, e = plan.block_rows(b)
        return (np.asarray(read_lines(s, e)) * plan.options.gain).astype(np.complex64)

    def finish(self, plan):
        raw, (n, m) = plan.raw, plan.output_shape
        rng = raw.radar.first_range_m + np.arange(m) * 299792458.0 / (2 * raw.radar.range_sampling_rate_hz)
        z = np.zeros((1, m))
        return SLC.from_raw(raw, image=np.zeros((0, 0), np.complex64), azimuth_time=raw.azimuth_time,
                            slant_range=rng, doppler=DopplerUsed(np.zeros(1), rng, z, z - 1.0, z + 1.0),
                            algorithm=self.name, azimuth_spacing_m=1.0, first_full_line=0, last_full_line=n - 1,
                            parameters={"gain": plan.options.gain})


@pytest.fixture
def toy():
    FOCUSERS.register("toy", Toy())
    yield
    FOCUSERS.unregister("toy")


def test_toy_focuser_end_to_end_through_the_cli(cli, tmp_path, toy):
    from sarcli.io.raw import write_raw
    from sarcli.io.slc import read_slc

    from .synth import scene

    raw = scene([], n_lines=150, n_samples=40)
    rng = np.random.default_rng(7)
    raw.echo[:] = (rng.standard_normal(raw.echo.shape) + 1j * rng.standard_normal(raw.echo.shape)).astype(np.complex64)
    write_raw(tmp_path / "raw.h5", raw)
    r = cli("focus", tmp_path / "raw.h5", "-o", tmp_path / "toy.h5", "--algorithm", "toy", "--set", "gain=2.5",
            "--json")
    assert r.exit_code == 0, r.stderr
    rep = json.loads(r.stdout)
    assert rep["algorithm"] == "toy" and rep["parameters"]["gain"] == 2.5
    slc = read_slc(tmp_path / "toy.h5")
    assert slc.algorithm == "toy"
    np.testing.assert_array_equal(slc.image, (raw.echo * 2.5).astype(np.complex64))
    assert slc.parameters["config"]["options"] == {"gain": 2.5}  # the workflow's config travels with the product
    r = cli("focus", tmp_path / "raw.h5", "-o", tmp_path / "x.h5", "--algorithm", "toy", "--set", "bogus=1")
    assert r.exit_code == 2 and r.stderr.count("\n") == 1 and "bogus" in r.stderr and "gain" in r.stderr
    assert not (tmp_path / "x.h5").exists()


def test_unknown_algorithm_lists_the_registered_ones(cli, tmp_path, toy):
    r = cli("focus", tmp_path / "raw.h5", "-o", tmp_path / "x.h5", "--algorithm", "chirp-scaling")
    assert r.exit_code == 2 and "toy" in r.stderr and "rd" in r.stderr and r.stderr.count("\n") == 1
