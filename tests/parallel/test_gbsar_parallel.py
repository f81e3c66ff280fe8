"""GB-SAR time series as a task graph over pixel blocks: groups of images added to running sums give the
whole-stack coherence, mean amplitude and PS values bit for bit, here and on a Dask cluster."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.parallel.executor import Here, OnCluster
from sarcli.parallel.gbsar import Series, coherence_graph, ps_values
from tests.conftest import run_cli
from tests.gbsar.test_cli import _scan


@pytest.fixture(scope="module")
def images(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("series")
    out = []
    for k in range(5):
        scan = _scan(run_cli, tmp, f"p{k}", seed=k + 1, minute=10 * k)
        img = tmp / f"p{k}.img.h5"
        assert run_cli("gbsar", "focus", scan, "-o", img).exit_code == 0
        out.append(img)
    return out


def _reference(paths):
    """The former whole-stack computation (np.stack of every image)."""
    from sarcli.gbsar.interferometry import support
    from sarcli.gbsar.timeseries import temporal_coherence
    from sarcli.io.gbsar_image import read_gbsar_image

    imgs = [read_gbsar_image(p) for p in paths]
    stack = np.stack([im.pol("VV") for im in imgs])
    ok = np.logical_and.reduce([support(im, "VV") for im in imgs])
    return np.where(ok, temporal_coherence(stack), np.nan).astype(np.float32), np.mean(np.abs(stack), axis=0), \
        int(ok.sum()), stack


def _reduce(ex, series, n_r, rows, group):
    blocks = [(a, min(a + rows, n_r)) for a in range(0, n_r, rows)]
    futures = dict(zip(coherence_graph(ex, series, blocks, group), blocks, strict=True))
    gamma, amp, n_ok = None, None, 0
    for f in ex.as_completed(futures):
        (a, b), (g, m, k) = futures[f], f.result()
        if gamma is None:
            gamma, amp = np.empty((n_r, g.shape[1]), g.dtype), np.empty((n_r, m.shape[1]), m.dtype)
        gamma[a:b], amp[a:b], n_ok = g, m, n_ok + k
    return gamma, amp, n_ok


def _check(ex, images):
    gamma, amp, n_ok, stack = _reference(images)
    series = Series(tuple(map(str, images)), (0,) * len(images), "VV")
    n_r = gamma.shape[0]
    for rows, group in ((7, 2), (n_r, 16), (1, 3)):  # blocks not dividing the rows; groups not dividing 5
        g, m, k = _reduce(ex, series, n_r, rows, group)
        np.testing.assert_array_equal(g, gamma)
        np.testing.assert_array_equal(m, amp)
        assert k == n_ok
    r, c = np.array([0, 3, 5]), np.array([2, 0, 9])
    got = np.hstack([ex.submit(ps_values, series, (4, 11), lo, min(lo + 2, 5), r, c).result() for lo in (0, 2, 4)])
    np.testing.assert_array_equal(got, stack[:, 4 + r, c].T)


@pytest.mark.slow
def test_coherence_graph_here_equals_the_whole_stack(images):
    _check(Here(), images)


@pytest.mark.slow
def test_coherence_graph_on_a_cluster_equals_the_whole_stack(images):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, protocol="tcp",
                      dashboard_address=None) as cluster, Client(cluster, set_as_default=False) as client:
        _check(OnCluster(client), images)


@pytest.mark.slow
def test_coherence_workflow_on_a_cluster_focuses_scans_and_equals_the_serial_run(images, tmp_path):
    """Scans among the inputs are focused as tasks on the first image's grid: the PS product is the
    serial one's (the existing workflow test checks the serial run against the whole stack)."""
    from distributed import LocalCluster

    from sarcli.io.interferogram import read_ps
    from sarcli.workflows.gbsar_coherence import Config, run

    scans = [p.with_name(p.name.replace(".img", "")) for p in images[3:]]
    inputs = (*images[:3], *scans)
    serial = run(Config(images=inputs, output=tmp_path / "serial.h5", threshold=0.99, block_rows=9))
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, protocol="tcp",
                      dashboard_address=None) as cluster:
        par = run(Config(images=inputs, output=tmp_path / "par.h5", threshold=0.99, block_rows=9,
                         scheduler=cluster.scheduler_address))
    assert par.n_ps == serial.n_ps > 0
    a, b = read_ps(tmp_path / "serial.h5"), read_ps(tmp_path / "par.h5")
    for key in ("coherence", "ps_row", "ps_col", "ps_phase", "ps_displacement_mm"):
        np.testing.assert_array_equal(a[key], b[key])
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # temporary images removed
