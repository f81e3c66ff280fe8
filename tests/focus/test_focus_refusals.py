"""``sarcli focus`` refuses, in one line and before any work, what would destroy an input or give a
wrong answer (docs/focusing.md, "What `sarcli focus` refuses"): an output that is the input (same path,
through GeoTIFF/PNG options too, or a hard link), a raw product its reader marked not focusable, a Doppler model
whose PRF ambiguity is unresolved (unless accepted, or the centroid is given)."""

from __future__ import annotations

import hashlib
import os

import numpy as np
import pytest

from .synth import scene


def _one_line(r, needle: str) -> None:
    assert r.exit_code != 0
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sarcli: error: ") and needle in lines[0], r.stderr


def _sha(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture
def raw_file(tmp_path):
    from sarcli.io.raw import write_raw

    write_raw(tmp_path / "raw.h5", scene([(850e3 + 300 * 6.245, 0.2, 1.0)], n_lines=600, n_samples=600))
    return tmp_path / "raw.h5"


@pytest.mark.parametrize("option", ["-o", "--geotiff", "--geotiff-slant", "--quicklook"])
def test_output_equal_to_the_input_is_refused(cli, raw_file, option):
    before = _sha(raw_file)
    args = ["-o", raw_file.parent / "slc.h5"] if option != "-o" else []
    r = cli("focus", raw_file, *args, option, raw_file, "--fdc", "0", "--fr", "-2000")
    _one_line(r, "refusing to overwrite an input")
    assert _sha(raw_file) == before
    assert not (raw_file.parent / "slc.h5").exists()


def test_hard_link_to_the_input_is_refused(cli, raw_file):
    link = raw_file.parent / "link.h5"
    os.link(raw_file, link)
    before = _sha(raw_file)
    r = cli("focus", raw_file, "-o", link, "--fdc", "0", "--fr", "-2000")
    _one_line(r, "refusing to overwrite an input")
    assert _sha(raw_file) == before


def test_unfocusable_product_is_refused_with_the_readers_reason(cli, tmp_path):
    from sarcli.io.raw import write_raw

    raw = scene([], n_lines=64, n_samples=100)
    raw.extra_attrs = {"focusable": False, "not_focusable_reason": "Sentinel-1 TOPS burst: deburst and deramp first"}
    write_raw(tmp_path / "tops.h5", raw)
    r = cli("focus", tmp_path / "tops.h5", "-o", tmp_path / "slc.h5", "--fdc", "0", "--fr", "-2000")
    _one_line(r, "Sentinel-1 TOPS burst: deburst and deramp first")
    assert not (tmp_path / "slc.h5").exists()


class _Unresolved:
    """An estimated model whose ambiguity could not be resolved (what sarcli.doppler flags)."""

    ambiguity_resolved = False

    def fdc(self, r, t):
        return np.zeros(np.broadcast(np.asarray(r), np.asarray(t)).shape)

    def fr(self, r, t):
        return -2 * 7000.0**2 / (0.0566 * np.broadcast_to(np.asarray(r, float), np.broadcast(
            np.asarray(r), np.asarray(t)).shape))


def test_unresolved_ambiguity_needs_an_explicit_choice(cli, raw_file, monkeypatch):
    import sarcli.doppler.api as api

    monkeypatch.setattr(api, "estimate_doppler", lambda raw, **kw: _Unresolved())
    out = raw_file.parent / "slc.h5"
    r = cli("focus", raw_file, "-o", out)
    _one_line(r, "--accept-unresolved-ambiguity")
    assert "--fdc" in r.stderr and not out.exists()
    r = cli("focus", raw_file, "-o", out, "--accept-unresolved-ambiguity")
    assert r.exit_code == 0, r.stderr
    r = cli("focus", raw_file, "-o", raw_file.parent / "given.h5", "--fdc", "0", "--fr", "-2000")
    assert r.exit_code == 0, r.stderr
