"""Workflows: one module per step, file to file. The Python API of sarcli and what Dask runs.

Each module ``sarcli.workflows.<step>`` defines

- ``Config``: a frozen dataclass of everything the step needs (input and output paths included),
  built from a mapping with :func:`sarcli.config.from_mapping` (a TOML table, the CLI's options) and
  stored in the products it writes (their ``parameters``);
- ``run(config, provenance=None, progress=None) -> Report``: does the work, writes the products
  atomically, returns a report (a dataclass with ``to_dict()`` and ``lines()``).

The CLI only parses options into a ``Config``, calls ``run`` and prints the report; ``sarcli run
steps.toml`` runs the tables of a TOML file (``[focus]``, ``[doppler]``, ...) in order. Workflows
are registered in :data:`WORKFLOWS` by step name.
"""

from sarcli.registry import Registry

WORKFLOWS: Registry = Registry("workflow", "sarcli.workflows", {
    "ati_compensate": "sarcli.workflows.ati_compensate",
    "ati_detect": "sarcli.workflows.ati_detect",
    "ati_estimate": "sarcli.workflows.ati_estimate",
    "ati_montecarlo": "sarcli.workflows.ati_montecarlo",
    "batch": "sarcli.workflows.batch",
    "calibrate": "sarcli.workflows.calibrate",
    "corner_reflectors": "sarcli.workflows.corner_reflectors",
    "design": "sarcli.workflows.design",
    "doppler": "sarcli.workflows.doppler",
    "export": "sarcli.workflows.export",
    "focus": "sarcli.workflows.focus",
    "gbsar_coherence": "sarcli.workflows.gbsar_coherence",
    "gbsar_emulate": "sarcli.workflows.gbsar_emulate",
    "gbsar_focus": "sarcli.workflows.gbsar_focus",
    "gbsar_import": "sarcli.workflows.gbsar_import",
    "gbsar_interfere": "sarcli.workflows.gbsar_interfere",
    "gbsar_monitor": "sarcli.workflows.gbsar_monitor",
    "gbsar_plan": "sarcli.workflows.gbsar_plan",
    "gbsar_polarimetry": "sarcli.workflows.gbsar_polarimetry",
    "gbsar_repeat": "sarcli.workflows.gbsar_repeat",
    "gbsar_scan": "sarcli.workflows.gbsar_scan",
    "gbsar_series": "sarcli.workflows.gbsar_series",
    "gbsar_serve": "sarcli.workflows.gbsar_serve",
    "gbsar_simulate": "sarcli.workflows.gbsar_simulate",
    "info": "sarcli.workflows.info",
    "ingest": "sarcli.workflows.ingest",
    "optical_compare": "sarcli.workflows.optical_compare",
    "orbit_accuracy": "sarcli.workflows.orbit_accuracy",
    "orbit_info": "sarcli.workflows.orbit_info",
    "orbit_interpolate": "sarcli.workflows.orbit_interpolate",
    "quality": "sarcli.workflows.quality",
    "run": "sarcli.workflows.run",
    "simulate": "sarcli.workflows.simulate",
})
