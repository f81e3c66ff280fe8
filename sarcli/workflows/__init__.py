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
    "focus": "sarcli.workflows.focus",
    "quality": "sarcli.workflows.quality",
})
