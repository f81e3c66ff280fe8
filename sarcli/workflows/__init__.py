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
    "doppler": "sarcli.workflows.doppler",
    "gbsar_coherence": "sarcli.workflows.gbsar_coherence",
    "gbsar_emulate": "sarcli.workflows.gbsar_emulate",
    "gbsar_focus": "sarcli.workflows.gbsar_focus",
    "gbsar_interfere": "sarcli.workflows.gbsar_interfere",
    "gbsar_monitor": "sarcli.workflows.gbsar_monitor",
    "gbsar_plan": "sarcli.workflows.gbsar_plan",
    "gbsar_polarimetry": "sarcli.workflows.gbsar_polarimetry",
    "gbsar_repeat": "sarcli.workflows.gbsar_repeat",
    "gbsar_scan": "sarcli.workflows.gbsar_scan",
    "gbsar_series": "sarcli.workflows.gbsar_series",
    "gbsar_serve": "sarcli.workflows.gbsar_serve",
    "gbsar_simulate": "sarcli.workflows.gbsar_simulate",
})
