"""The noise power of the real Sentinel-1 noise packet (``../shared/data/s1_l0_packets``), as the radiometry
takes it (:func:`sarcli.calibration.radiometry.noise_power`), against the independent reference decode of
the same packet, and the statistics a receiver's thermal noise must have."""

from __future__ import annotations

import numpy as np
import pytest

from tests.sentinel1.conftest import load_reference


def test_noise_power_of_the_real_noise_packet(s1_packets, tmp_path):
    from sarcli.calibration.radiometry import noise_power
    from sarcli.io.sentinel1.product import read_level0

    ref = load_reference(s1_packets / "000000-noise.npz")["udf"].astype(np.complex128)
    path = tmp_path / "real.dat"  # a product needs an echo: the noise, calibration and echo packets as one stream
    path.write_bytes(b"".join((s1_packets / f"{n}.dat").read_bytes()
                              for n in ("000000-noise", "000008-txcal", "000408-echo")))
    (raw,) = read_level0(path).products.values()
    p, how = noise_power(raw)
    assert "noise line" in how
    # the reference decoder's samples, plain numpy: the variance (the receiver's DC offset, a bias of 0.2 of
    # a code on I here, is not thermal noise); 3.4 codes^2 (5.3 dB) in this packet
    x = ref - ref.mean()
    want = float(np.mean(np.abs(x) ** 2))
    assert p == pytest.approx(want, rel=1e-12)
    assert abs(ref.mean()) ** 2 < 0.05 * want
    # thermal noise: I and Q of equal power (circular), each half the total; n samples give each component's
    # power to sqrt(2 / n) (Gaussian): 5 sigma bounds
    n = x.size
    assert abs(np.mean(x.real**2) / np.mean(x.imag**2) - 1.0) < 5 * np.sqrt(2 * 2 / n)
    # Gaussian: E|x|^4 = 2 (E|x|^2)^2 for circular complex noise (the kurtosis estimate's relative std is
    # about sqrt(20 / n) here)
    assert np.mean(np.abs(x) ** 4) / want**2 == pytest.approx(2.0, rel=5 * np.sqrt(20 / n))
