"""``estimate_doppler(raw) -> PolyDoppler``: the absolute Doppler centroid and the Doppler rate of a raw
product ([Koh2003]'s hybrid method, plus data-only routes).

The stages are in :mod:`sarcli.doppler.pipeline`, the centroid estimators in
:mod:`sarcli.doppler.estimators` (plug-ins), the knobs in :class:`~sarcli.doppler.options.DopplerOptions`.
The ground under the beam is an explicit input (``terrain``, default the WGS-84 ellipsoid): the
simulator's ``/truth`` is never read.
"""

from __future__ import annotations

import warnings

from sarcli.config import to_mapping
from sarcli.doppler import inputs, pipeline
from sarcli.doppler.options import DopplerOptions
from sarcli.model.doppler import PolyDoppler
from sarcli.model.doppler_summary import low_confidence_note
from sarcli.model.raw import RawProduct
from sarcli.model.terrain import ConstantHeight, Terrain

_UNRESOLVED = {
    "none": "no orbit, and the swath is not longer than the pulse for the data-only estimate",
    "orbit": "the orbit prediction is half-way between two ambiguities and the data could not decide, or the "
             "orbit/attitude and the data disagree",
    "data": "the data-only estimate found no usable range block",
}


def estimate_doppler(raw: RawProduct, options: DopplerOptions | None = None, *, terrain: Terrain | None = None,
                     progress: pipeline.Progress | None = None, consume: bool = False) -> PolyDoppler:
    """Absolute Doppler centroid and Doppler rate of ``raw`` (``sarcli.doppler.pipeline``).

    ``options``: every knob (default :class:`DopplerOptions()`); ``terrain``: the height of the ground
    under the beam, for the geometric model (default ``ConstantHeight(0)``: the ellipsoid);
    ``progress(stage, done, total)`` after each stage. A product the estimate cannot be trusted on is
    refused (``sarcli.doppler.inputs``); an ambiguity no source could decide is reported
    (``model.ambiguity_resolved`` False) with one warning. The input is not modified, unless ``consume``:
    then the caller gives ``raw.echo`` up and receiver-gain steps are undone in it instead of in a copy
    (one echo's memory less: 1.1 GB on a full scene). The estimate is the same either way.
    """
    options = DopplerOptions() if options is None else options
    terrain = ConstantHeight(0.0) if terrain is None else terrain
    prepared, steps = inputs.prepare(raw, options.gain_steps, consume)
    parameters = {**to_mapping(options, keep_none=True), "terrain": terrain.describe()}
    model = pipeline.run(prepared, options, terrain, steps, parameters, progress)
    s = model.summary
    if s is not None and not s.ambiguity_resolved:
        why = "ambiguity mode none" if options.ambiguity == "none" else _UNRESOLVED[s.ambiguity_source]
        warnings.warn(f"Doppler ambiguity not resolved ({why}): fdc {s.fdc_hz:.1f} Hz "
                      f"assumes ambiguity {s.ambiguity}; give it with --ambiguity-value N, or use a product with an "
                      "orbit", stacklevel=2)
    elif (note := low_confidence_note(s)) is not None:
        warnings.warn(note, stacklevel=2)
    return model
