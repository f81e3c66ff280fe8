"""Sentinel-1 Level-0: instrument source packets -> raw products (decoder, ancillary data, writer).

See ``docs/sentinel1.md``. Modules: :mod:`.constants` (specification tables), :mod:`.headers`
(packet walking, header fields), :mod:`.decode` (user data decoders, numba), :mod:`.reference`
(plain-Python decoders for the tests), :mod:`.ancillary` (orbit and attitude from the
sub-commutated words), :mod:`.product` (Level-0 file -> raw products), :mod:`.encode` (the inverse:
packet writer for tests and the simulator).
"""
