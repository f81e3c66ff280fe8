"""Stripmap focusing: Range-Doppler algorithm (RDA), time-domain backprojection, quality metrics.

Focusers are plug-ins (:mod:`sarcli.focus.base`: ``plan / focus_block / finish``) registered in
:data:`FOCUSERS` by name; ``sarcli focus --algorithm NAME`` and ``sarcli.workflows.focus`` look them
up there. Built in (imported only when asked for: looking up ``rd`` does not import the optical
emulator): ``rd`` (:class:`sarcli.focus.rda.RangeDoppler`), ``csa`` (chirp scaling,
:class:`sarcli.focus.csa.ChirpScaling`), ``backprojection``
(:class:`sarcli.focus.bp_product.Backprojection`) and ``optical`` (the AOD/CCD emulation,
:mod:`sarcli.optical.focus_plugin`). Others register with ``FOCUSERS.register(name, obj)`` or an
entry point in the ``sarcli.focusers`` group.
Also built in: ``ffbp``, fast factorized backprojection (:class:`sarcli.focus.ffbp_product.Ffbp`).

In memory: :func:`sarcli.focus.rda.focus_rd` ``(raw, doppler, channel=0, **options) -> SLC`` and
:func:`sarcli.focus.base.focus_in_memory` for any focuser.

A Doppler model is any object with vectorized ``fdc(range_m, t)`` (absolute centroid, Hz) and
``fr(range_m, t)`` (Doppler rate, Hz/s, negative), ``range_m`` the slant range of the RAW range sample
(beam-centre range) and ``t`` the raw (pulse) azimuth time in s after the product epoch.
"""

from sarcli.focus.base import check_focuser
from sarcli.registry import Registry

FOCUSERS: Registry = Registry("focuser", "sarcli.focusers", {
    "rd": "sarcli.focus.rda:RD",
    "csa": "sarcli.focus.csa:CSA",
    "backprojection": "sarcli.focus.bp_product:BACKPROJECTION",
    "omegak": "sarcli.focus.omegak:OMEGAK",
    "ffbp": "sarcli.focus.ffbp_product:FFBP",
    "optical": "sarcli.optical.focus_plugin:OPTICAL",
}, check=check_focuser)
