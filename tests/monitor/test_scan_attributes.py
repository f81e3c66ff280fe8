"""The two scan attributes ``gbsar monitor`` reads without loading a scan: the status (to resume) and
the epoch (the resumed scan's clock); a scan lacking them is handled in one line, not a traceback."""

from __future__ import annotations

import calendar

import h5py
import numpy as np
import pytest

from sarcli.errors import ProductError
from sarcli.io.scan import write_scan
from sarcli.model.gbsar import Scan
from sarcli.workflows.gbsar_monitor import _scan_epoch, _status


@pytest.fixture
def scan_file(tmp_path):
    n_stops, n_freq = 3, 5
    s21 = np.ones((1, n_stops, n_freq), np.complex64)
    scan = Scan(s21=s21, frequency=np.linspace(5.2e9, 5.4e9, n_freq), rail_position=np.arange(n_stops) * 0.05,
                rail_height=np.zeros(n_stops), polarizations=("VV",), epoch_utc="2026-11-22T06:30:00Z",
                status="partial")
    path = tmp_path / "scan.h5"
    write_scan(path, scan)
    return path


def test_epoch_and_status_read_from_the_attributes(scan_file):
    assert _scan_epoch(scan_file) == calendar.timegm((2026, 11, 22, 6, 30, 0))
    assert _status(scan_file) == "partial"


def test_missing_epoch_refused_and_missing_status_unknown(scan_file):
    with h5py.File(scan_file, "a") as f:
        del f.attrs["epoch_utc"]
        del f.attrs["status"]
    with pytest.raises(ProductError, match="attribute 'epoch_utc' missing"):
        _scan_epoch(scan_file)
    assert _status(scan_file) == "unknown"
