"""The device limitations of the emulated AOD/CCD processor: each one effect, switched on by listing it.

With none listed the emulator is the ideal coherent processor the optics approximates (complex
correlation in range and azimuth on the CCD grid); each listed limitation adds one physical effect:

    aod_aperture        the AOD holds only T_a = X / v_a of echo: chirps reaching past it are cut
    aod_bandwidth       the AOD passband (30 MHz) filters the heterodyned echo
    light_pulse         the flash lasts tau_L: the intensity is smeared over v_a tau_L of acoustic travel
    detector_intensity  the CCD records |g + A exp(j theta)|^2 (reference carrier + bias), not g
    mask                the azimuth reference is the real transmittance (1/2)(1 + cos(theta + psi)) of eq. 12
    ccd_size            finite CCD rows (491: caps the azimuth aperture) and columns (384: caps the swath)
    ccd_pixels          each column integrates over its pixel width instead of sampling a point
    adc                 the charge is read out through an n-bit converter spanning its full range
"""

from __future__ import annotations

from sarcli.errors import SarcliError

LIMITATIONS: dict[str, str] = {
    "aod_aperture": "finite AOD time aperture T_a = X / v_a",
    "aod_bandwidth": "AOD passband around its centre frequency",
    "light_pulse": "finite flash duration (intensity smear v_a * tau_L)",
    "detector_intensity": "square-law detection with reference carrier and bias terms",
    "mask": "real mask transmittance (1/2)(1 + cos(2 pi u0 x + psi)) of [KimAODCCD, eq. 12]",
    "ccd_size": "finite CCD rows (azimuth aperture) and columns (swath)",
    "ccd_pixels": "pixel-area integration across range",
    "adc": "n-bit read-out over the full charge range",
}

ALL = tuple(LIMITATIONS)


def parse(names: str | list[str] | tuple[str, ...] | None) -> frozenset[str]:
    """Validate limitation names ('all', 'none', a comma list or a sequence)."""
    if names is None:
        return frozenset()
    if isinstance(names, str):
        if names.strip() in ("", "none"):
            return frozenset()
        if names.strip() == "all":
            return frozenset(ALL)
        names = [n.strip() for n in names.split(",") if n.strip()]
    unknown = sorted(set(names) - set(ALL))
    if unknown:
        raise SarcliError(f"unknown optical limitation(s) {', '.join(unknown)}; known: {', '.join(ALL)}, all, none")
    return frozenset(names)
