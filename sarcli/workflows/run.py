"""``sarcli run STEPS.toml``: run the workflows named by the file's top-level tables, in file order.

Each table is one step: its name is a workflow (:data:`sarcli.workflows.WORKFLOWS`: ``simulate``,
``ingest``, ``info``, ``doppler``, ``focus``, ...) and its keys are that workflow's ``Config``, exactly as
the workflow documents them (``sarcli.config.from_mapping``)::

    [simulate]
    scene = "samples/rs1_point.toml"
    output = "demo/raw.h5"

    [info]
    sources = ["demo/raw.h5"]

Every step is checked before the first one runs: an unknown step, an unknown option or a bad value is
one line naming the file, the step and the key, and nothing runs. Paths are relative to the current
folder (as on the command line). To run a workflow twice, use an array of tables (``[[info]]``): TOML
keeps one key per name, so all its entries run one after the other at the place of the first one.
Each step's products record the command line with the step's name (``sarcli run steps.toml [focus]``).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sarcli.config import from_mapping, load_toml
from sarcli.errors import ConfigError, SarcliError
from sarcli.io.provenance import Provenance, current
from sarcli.workflows import WORKFLOWS, base

_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Config:
    """steps: the steps file (TOML)."""

    steps: Path


@dataclass(frozen=True)
class Step:
    """One step to run: its workflow name, module and validated configuration."""

    name: str
    module: Any
    config: Any


@dataclass
class Report(base.Report):
    """The report of every step, in order."""

    steps: list[tuple[str, Any]]

    def to_dict(self) -> dict[str, Any]:
        return {"steps": [{"step": name, "report": r.to_dict()} for name, r in self.steps]}

    def lines(self) -> list[str]:
        out: list[str] = []
        for name, r in self.steps:
            out.append(f"[{name}]")
            out += r.lines()
        return out


def load_steps(path: Path) -> list[Step]:
    """Every step of the file, validated (module docstring); one :class:`ConfigError` line otherwise."""
    doc = load_toml(path)
    steps: list[Step] = []
    for name, value in doc.items():
        tables = value if isinstance(value, list) else [value]
        if not tables or not all(isinstance(t, Mapping) for t in tables):
            raise ConfigError(f"{path}: {name} = {value!r} is not a step table; write [{name}] with the "
                              "step's options")
        if name == "run":
            raise ConfigError(f"{path}: a [run] step (a steps file inside a steps file) is not allowed")
        if name not in WORKFLOWS:
            known = [n for n in WORKFLOWS.names() if n != "run"]
            raise ConfigError(f"{path}: unknown step [{name}]; known steps: {', '.join(known)}")
        module = WORKFLOWS.get(name)
        for i, t in enumerate(tables):
            where = f"{path}: {name}" + (f"[{i}]" if isinstance(value, list) else "")
            try:
                config = from_mapping(module.Config, t, where)
            except ConfigError as e:  # a check of the Config itself names the key, not the file
                raise e if str(e).startswith(where) else ConfigError(f"{where}: {e}") from None
            steps.append(Step(name, module, config))
    if not steps:
        raise ConfigError(f"{path}: no step (a step is a table such as [simulate] or [info])")
    return steps


def run(config: Config, provenance: Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Validate every step, then run them in order; a failing step stops the run (its message names it)."""
    with base.using(provenance):
        steps = load_steps(Path(config.steps))
        caller = current().command_line
        reports: list[tuple[str, Any]] = []
        for k, step in enumerate(steps):
            _log.info("step %d of %d: %s", k + 1, len(steps), step.name)
            try:
                report = step.module.run(step.config, provenance=Provenance(f"{caller} [{step.name}]"),
                                         progress=progress)
            except SarcliError as e:
                raise type(e)(f"step [{step.name}]: {e}") from None
            reports.append((step.name, report))
        return Report(reports)
