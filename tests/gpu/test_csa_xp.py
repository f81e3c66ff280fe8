"""The CSA block on the array namespace (sarcli.gpu.csa_xp) with xp = numpy, against the numba CPU path, within
:func:`sarcli.gpu.csa_xp.difference_bound` (the CPU kernel's phase span interpolation, 1e-3 rad, plus
float32 round-off); point-target metrics identical to the stated digits."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.focus.csa import focus_csa
from sarcli.focus.quality import point_target_metrics
from sarcli.gpu import csa_xp
from sarcli.model.doppler import GeometricDoppler
from tests.focus.synth import C, beam_offset, scene, sin_squint

PRF, FS = 1500.0, 24e6
R0 = 850e3 + 384.3 * C / (2 * FS)


@pytest.mark.parametrize("fdc,kw", [
    (0.0, {}),
    (-3.4 * PRF, {"block_lines": 512}),
    (-3.4 * PRF, {"precision": "double", "interpolator": "linear", "src": False}),
    (150.0, {"interpolator": "nearest", "range_oversample": 1}),
])
def test_gpu_csa_block_equals_cpu_within_the_derived_bound(monkeypatch, fdc, kw):
    monkeypatch.setenv("NUMBA_ENABLE_CUDASIM", "1")  # cuda = the simulator: xp is numpy
    eta0 = 0.34 + 0.37 / PRF - beam_offset(R0, fdc)
    raw = scene([(R0, eta0, 1.0), (R0 + 80 * C / (2 * FS), eta0 + 0.04, 0.5)], fdc=fdc, n_lines=768,
                n_samples=640)
    dop = GeometricDoppler(7000.0, sin_squint(fdc), 0.0566)
    cpu = focus_csa(raw, dop, **kw)
    gpu = focus_csa(raw, dop, device="cuda", **kw)
    peak = float(np.abs(cpu.image).max())
    taps = {"nearest": 1, "linear": 2}.get(kw.get("interpolator", "sinc8"), 8)
    n_az, n_r = cpu.parameters["azimuth_fft_length"], cpu.parameters["range_fft_length"]
    assert np.max(np.abs(gpu.image - cpu.image)) <= csa_xp.difference_bound(n_az, n_r, taps,
                                                                              kw.get("precision", "single")) * peak
    row, col = np.unravel_index(int(np.argmax(np.abs(cpu.image))), cpu.image.shape)
    m_cpu, m_gpu = point_target_metrics(cpu.image, row, col), point_target_metrics(gpu.image, row, col)
    for key in ("irw_range_px", "irw_azimuth_px"):
        assert round(m_cpu[key], 3) == round(m_gpu[key], 3)
    for key in ("pslr_range_db", "pslr_azimuth_db"):
        assert round(m_cpu[key], 2) == round(m_gpu[key], 2)
    assert abs(m_cpu["row"] - m_gpu["row"]) < 1e-3 and abs(m_cpu["col"] - m_gpu["col"]) < 1e-3


def test_chirp_scale_rows_is_the_kernels_phase():
    from sarcli.focus.csa import chirp_scale

    rng = np.random.default_rng(2)
    x = rng.standard_normal((5, 300)) + 1j * rng.standard_normal((5, 300))
    q2 = rng.uniform(-1e12, 1e12, 5) * np.pi
    tau_r = 5.7e-3 + rng.uniform(0, 1e-5, 5)
    ref = x.copy()
    chirp_scale(ref, 260, q2, tau_r, 5.7e-3, 1 / 24e6)
    np.testing.assert_allclose(csa_xp.chirp_scale_rows(np, x, 260, q2, tau_r, 5.7e-3, 1 / 24e6), ref, rtol=0,
                               atol=1e-9)
