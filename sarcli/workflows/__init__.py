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
    "ingest": "sarcli.workflows.ingest",
    "info": "sarcli.workflows.info",
    "simulate": "sarcli.workflows.simulate",
    "orbit_info": "sarcli.workflows.orbit_info",
    "orbit_interpolate": "sarcli.workflows.orbit_interpolate",
    "orbit_accuracy": "sarcli.workflows.orbit_accuracy",
    "ati_detect": "sarcli.workflows.ati_detect",
    "ati_estimate": "sarcli.workflows.ati_estimate",
    "ati_compensate": "sarcli.workflows.ati_compensate",
    "ati_montecarlo": "sarcli.workflows.ati_montecarlo",
    "optical_compare": "sarcli.workflows.optical_compare",
    "design": "sarcli.workflows.design",
    "run": "sarcli.workflows.run",
})
