"""Geometric and point-target calibration of focused images with surveyed corner reflectors.

Modules, one job each:

- ``reflectors``  corner-reflector CSV files (NISAR's 12-column format with survey history, validity
                  flags and plate velocity; the older UAVSAR 7-column format), survey selection and the
                  reflector's position at the acquisition time;
- ``predict``     the reflector's pixel by the zero-Doppler solve on the product's orbit, the local
                  along-track pixel spacing, incidence angle, and the propagation/geophysical
                  corrections a user must add before reading an offset as a geometry error;
- ``irf``         the measured impulse response (peak, IRW, PSLR, ISLR through
                  ``sarcli.focus.quality``) and the theoretical IRW of the product's processed bands and
                  spectral windows;
- ``analysis``    the per-reflector table (measured minus predicted offsets in metres, IRF metrics);
- ``plots``       one IRF picture per reflector (range and azimuth cuts, 2-D dB chip with the measured
                  and predicted positions);
- ``pointing``    the Doppler centroid measured on raw data against the one predicted from orbit +
                  attitude (antenna pointing), with the standard error of the measurement;
- ``radiometry``  the radiometric model of a focused image (processing gain, antenna patterns, range
                  spreading, absolute constant K): beta0/sigma0/gamma0 look-up tables, the noise floor,
                  point-target RCS by integrated energy, the trihedral's theoretical RCS;
- ``products``    calibrated backscatter images (beta0, sigma0, gamma0 terrain-flattened over a DEM).

The command-level steps are ``sarcli.workflows.corner_reflectors`` and ``sarcli.workflows.calibrate``.
"""
