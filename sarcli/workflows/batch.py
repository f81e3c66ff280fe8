"""Workflow ``batch``: a folder of scenes -> raw -> Doppler -> SLC + GeoTIFF + quicklook, as ONE Dask task graph.

Every entry of ``input`` is a scene: a raw product (``NAME.h5``, product type ``raw``) or anything a
sensor reader recognises by sniffing (:mod:`sarcli.io.readers`: a CEOS scene folder ``NAME/``, a
folder ``NAME/`` holding a MATLAB block and its run parameters, a NISAR L0B file, ...), ingested first.
Other entries (hidden files, other sarcli products, files no reader recognises) are listed as ignored;
an entry a reader recognises as its format but cannot read, or a name used twice, is a failed input.
``geotiff`` (``auto``): a scene without an Earth orbit gets no GeoTIFF (a warning). Per scene, in
``output``::

    NAME.raw.h5       sarcli ingest SOURCE -o NAME.raw.h5                (sensor inputs only)
    NAME.doppler.h5   sarcli doppler RAW -o NAME.doppler.h5
    NAME.slc.h5, NAME.tif, NAME.png
                      sarcli focus RAW --doppler NAME.doppler.h5 -o NAME.slc.h5 --geotiff NAME.tif --quicklook NAME.png
    NAME.json         this scene's report: each step's status, time, worker, error and workflow report

Each step is a task calling the workflow's ``run(config, provenance)``; its provenance is the step's
own command line (above, with ``(sarcli batch IN -o OUT)``), never the worker's ``sys.argv``. A step
whose outputs all exist and are newer than all its inputs is skipped, as ``make batch`` does (the
steps after a rebuilt one are rebuilt). A bad input fails its own scene only; an unexpected failure
is retried once (:mod:`sarcli.parallel.graph`); the report ends with what failed and why.

Where: a ``LocalCluster`` (``workers`` processes x ``threads_per_worker`` threads, default one
process per core), the scheduler at ``scheduler`` (or ``$SARCLI_SCHEDULER``), or ``workers = 0``:
this process, one task after the other, without Dask. ``report``: Dask's performance report (HTML).
"""

from __future__ import annotations

import json
import logging
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from sarcli.config import from_mapping
from sarcli.errors import ConfigError, ProductError, SarcliError
from sarcli.workflows import WORKFLOWS
from sarcli.workflows.base import Progress, Provenance, Report, no_progress, using

log = logging.getLogger(__name__)

STEPS = ("ingest", "doppler", "focus")
#: focus Config fields a batch sets itself (the rest may be given in ``focus``)
_FOCUS_OWN = ("raw", "output", "doppler", "fdc", "fr", "geotiff", "quicklook", "workers", "threads_per_worker",
              "scheduler")


@dataclass(frozen=True)
class Config:
    """input: the folder of scenes; output: the products' folder (created; its parent must exist);
    workers / threads_per_worker / scheduler: where the tasks run (module docstring; ``workers = 0``:
    here, serially); report: Dask performance report HTML; retries: reruns of a task that failed
    unexpectedly; focus: further ``sarcli.workflows.focus.Config`` fields for every scene (``looks_az``,
    ``options = {block_lines = 2048}``, ``height_m``, ...); geotiff: ``auto`` a GeoTIFF for every scene
    with an Earth orbit (a scene without one is focused without it, with a warning), ``always`` (a scene
    without an orbit fails), ``never``."""

    input: Path
    output: Path
    workers: int | None = None
    threads_per_worker: int = 1
    scheduler: str | None = None
    report: Path | None = None
    retries: int = 1
    focus: dict[str, Any] = field(default_factory=dict)
    geotiff: Literal["auto", "always", "never"] = "auto"

    def __post_init__(self) -> None:
        if self.retries < 0:
            raise ConfigError(f"retries must be >= 0, got {self.retries}")
        if self.workers == 0:
            if self.scheduler is not None:
                raise ConfigError("--workers 0 runs the batch in this process: drop --scheduler")
            if self.report is not None:
                raise ConfigError("--report is Dask's performance report: it needs a cluster (not --workers 0)")
        else:
            self.cluster()
        if "geotiff" in self.focus:
            raise ConfigError("the batch's GeoTIFFs are chosen with --geotiff auto|always|never (option geotiff), "
                              "not --focus geotiff=...")
        own = sorted(set(self.focus) & set(_FOCUS_OWN))
        if own:
            raise ConfigError(f"focus options {', '.join(own)} are set by the batch for every scene")
        from sarcli.workflows import focus

        from_mapping(focus.Config, {**self.focus, "raw": "raw.h5", "output": "slc.h5"}, "--focus")

    def cluster(self):
        """The :class:`sarcli.parallel.cluster.ClusterSpec`, or None (``workers = 0``: this process)."""
        if self.workers == 0:
            return None
        from sarcli.parallel.cluster import cluster_spec

        return cluster_spec(self.scheduler, self.workers, self.threads_per_worker)


@dataclass(frozen=True)
class Scene:
    """name (output stem), source (the entry of the input folder), reader (None: a raw product)."""

    name: str
    source: Path
    reader: str | None


@dataclass
class BatchReport(Report):
    """scenes: per scene its steps' status (done / failed / skipped / up to date) and report file;
    failures: scene, step (``input``: the entry itself) and why; ignored: entries that are not scenes,
    and why."""

    input: str
    output: str
    where: str
    scenes: list[dict[str, Any]]
    failures: list[dict[str, str]]
    ignored: list[dict[str, str]]
    counts: dict[str, int]
    wall_s: float
    performance_report: str | None = None

    def lines(self) -> list[str]:
        width = max([5] + [len(s["scene"]) for s in self.scenes])
        out = [f"{'scene':<{width}}  " + "  ".join(f"{s:<10}" for s in STEPS)]
        for s in self.scenes:
            out.append(f"{s['scene']:<{width}}  " + "  ".join(f"{s['steps'].get(k, '-'):<10}" for k in STEPS))
        c = self.counts
        out.append(f"{len(self.scenes)} scene(s) on {self.where} in {self.wall_s:.1f} s: {c['done']} task(s) done, "
                   f"{c['up_to_date']} up to date, {c['failed']} failed, {c['skipped']} skipped"
                   + (f"; {len(self.ignored)} entr{'y' if len(self.ignored) == 1 else 'ies'} ignored"
                      if self.ignored else ""))
        for s in self.scenes:
            if s.get("warnings"):
                out.append(f"{s['scene']}: " + ", ".join(f"{n} warning(s) in {k}" for k, n in s["warnings"].items())
                           + f" (see {s['report']})")
        if self.performance_report:
            out.append(f"Dask performance report: {self.performance_report}")
        return out

    def failure_lines(self) -> list[str]:
        """The table of what failed and why (empty when nothing failed)."""
        if not self.failures:
            return []
        width = max(len(f["scene"]) for f in self.failures)
        return ["failed:"] + [f"  {f['scene']:<{width}}  {f['step']:<8}  {f['error']}" for f in self.failures]


# --------------------------------------------------------------------------------------------------------
# Scenes


def _sniff(path: Path) -> tuple[str | None, str | None]:
    """(reader name, None) when a reader accepts ``path``; (None, diagnosis) when one recognises its
    format but cannot read it; (None, None) when none recognises it."""
    from sarcli.io.readers import READERS

    diagnosis = None
    for name, reader in READERS.items():
        try:
            if reader.sniff([path]):
                return name, None
        except SarcliError as e:
            diagnosis = diagnosis or str(e)
        except (OSError, ValueError) as e:
            log.debug("reader %s could not sniff %s: %s", name, path, e)
    return None, diagnosis


def _product_type(path: Path) -> str | None:
    """The sarcli product type of an HDF5 file, None when it is not a readable sarcli product."""
    from sarcli.io.h5common import attr_str, open_product

    try:
        with open_product(path) as f:
            return attr_str(f, "product_type")
    except ProductError:
        return None


def discover(folder: Path) -> tuple[list[Scene], list[dict[str, str]], list[dict[str, str]]]:
    """(scenes, ignored, bad inputs) of ``folder`` (module docstring), in name order."""
    scenes: list[Scene] = []
    ignored: list[dict[str, str]] = []
    bad: list[dict[str, str]] = []
    names: dict[str, Path] = {}
    for entry in sorted(folder.iterdir()):
        if entry.name.startswith("."):
            continue
        name = entry.stem if entry.is_file() else entry.name
        ptype = _product_type(entry) if entry.is_file() and entry.suffix.lower() in (".h5", ".hdf5") else None
        if ptype is not None and ptype != "raw":
            ignored.append({"entry": entry.name, "why": f"a sarcli {ptype} product, not a raw product"})
            continue
        reader, why = (None, None) if ptype == "raw" else _sniff(entry)
        if ptype != "raw" and reader is None:
            if why is None:
                if entry.suffix.lower() in (".h5", ".hdf5"):
                    bad.append({"scene": name, "step": "input", "error": f"{entry}: neither a sarcli raw product nor "
                                "a file a sensor reader recognises"})
                elif entry.suffix.lower() == ".mat":
                    ignored.append({"entry": entry.name, "why": "a MATLAB file alone: put a block with its run "
                                    "parameters in a folder of its own, one scene"})
                else:
                    ignored.append({"entry": entry.name, "why": "no sensor reader recognises it"})
            else:
                bad.append({"scene": name, "step": "input", "error": why})
            continue
        if name in names:
            bad.append({"scene": name, "step": "input", "error": f"{entry.name} and {names[name].name} would both "
                        f"make {name}.slc.h5: rename one"})
            continue
        names[name] = entry
        scenes.append(Scene(name, entry, reader))
    return scenes, ignored, bad


# --------------------------------------------------------------------------------------------------------
# The graph


def run_step(step: str, config: Any, command_line: str, *upstream: Any) -> dict[str, Any]:
    """One task: workflow ``step`` with ``config``; its provenance is ``command_line``. ``upstream``:
    the results of the steps before it (their products are files: unused)."""
    report = WORKFLOWS.get(step).run(config, Provenance(command_line))
    if step == "ingest" and len(report.products) > 1:
        raise ProductError(f"{' '.join(map(str, config.sources))} holds {len(report.products)} data sets: a batch "
                           "focuses one per input; ingest it with 'sarcli ingest' and batch the raw products")
    return report.to_dict()


def run_focus(config: Any, command_line: str, geotiff: str, *upstream: Any) -> dict[str, Any]:
    """The focus task: with ``geotiff`` ``auto``, a raw product without an Earth orbit is focused without
    its GeoTIFF (a warning says so; the command line then has no ``--geotiff``)."""
    import dataclasses
    import warnings

    if geotiff == "auto" and config.geotiff is not None:
        from sarcli.io.raw import read_raw

        orbit = read_raw(config.raw, load_echo=False).orbit
        if orbit is None or orbit.frame == "LOCAL":
            warnings.warn(f"{config.raw}: no GeoTIFF: the scene has no Earth orbit "
                          f"({'no state vectors' if orbit is None else 'a LOCAL frame'}); SLC and quicklook only",
                          stacklevel=1)
            command_line = command_line.replace(f" --geotiff {config.geotiff}", "")
            config = dataclasses.replace(config, geotiff=None)
    return run_step("focus", config, command_line, *upstream)


def _newest(paths: list[Path]) -> float:
    """Latest modification time of the files (a folder: of everything inside it)."""
    times = []
    for p in paths:
        times.append(p.stat().st_mtime)
        if p.is_dir():
            times += [q.stat().st_mtime for q in p.rglob("*") if q.is_file()]
    return max(times)


def _up_to_date(inputs: list[Path], outputs: list[Path]) -> bool:
    """Every output exists and is newer than every input (make's rule)."""
    if not all(p.exists() for p in outputs):
        return False
    return min(p.stat().st_mtime for p in outputs) >= _newest(inputs)


@dataclass
class _Plan:
    scene: Scene
    outputs: dict[str, Path]
    steps: dict[str, tuple[Any, str]]  # step -> (config, command line); steps that must run, in order
    up_to_date: list[str]


def plan_scene(scene: Scene, out: Path, suffix: str, focus_extra: dict[str, Any], geotiff: str = "auto") -> _Plan:
    """What must run for ``scene`` (make's rule, step by step; a step after a rebuilt one is rebuilt)."""
    from sarcli.workflows import doppler, focus, ingest

    n = scene.name
    o = {"raw": out / f"{n}.raw.h5" if scene.reader else scene.source, "doppler": out / f"{n}.doppler.h5",
         "slc": out / f"{n}.slc.h5", "geotiff": out / f"{n}.tif", "quicklook": out / f"{n}.png",
         "report": out / f"{n}.json"}
    chain: list[tuple[str, list[Path], list[Path], Any, str]] = []
    if scene.reader:
        chain.append(("ingest", [scene.source], [o["raw"]],
                      ingest.Config(sources=(scene.source,), output=o["raw"], format=scene.reader),
                      f"sarcli ingest {scene.source} -o {o['raw']}"))
    chain.append(("doppler", [o["raw"]], [o["doppler"]], doppler.Config(raw=o["raw"], output=o["doppler"]),
                  f"sarcli doppler {o['raw']} -o {o['doppler']}"))
    tif = None if geotiff == "never" else o["geotiff"]
    fc = from_mapping(focus.Config, {**focus_extra, "raw": o["raw"], "output": o["slc"], "doppler": o["doppler"],
                                     "geotiff": tif, "quicklook": o["quicklook"]}, "batch focus")
    chain.append(("focus", [o["raw"], o["doppler"]], [o["slc"], o["quicklook"]] + ([] if geotiff != "always" else
                                                                                   [o["geotiff"]]), fc,
                  f"sarcli focus {o['raw']} --doppler {o['doppler']} -o {o['slc']}"
                  + ("" if tif is None else f" --geotiff {tif}") + f" --quicklook {o['quicklook']}"))
    steps: dict[str, tuple[Any, str]] = {}
    fresh: list[str] = []
    for step, ins, outs, config, cmd in chain:
        if not steps and _up_to_date(ins, outs):
            fresh.append(step)
        else:
            steps[step] = (config, cmd + suffix)
    return _Plan(scene, o, steps, fresh)


def _step_warnings(outcome: Any) -> list[str]:
    """A step's warnings: those raised while it ran and those its workflow caught and listed in its report
    (focus records its own), each once."""
    value = outcome.value
    own = value.get("warnings") if isinstance(value, dict) else getattr(value, "warnings", None)
    return list(dict.fromkeys([*outcome.warnings, *(own or ())]))


def _write_scene_report(plan: _Plan, outcomes: dict[str, Any]) -> None:
    from sarcli.io.atomic import atomic_path
    from sarcli.io.h5common import to_jsonable

    steps: list[dict[str, Any]] = [{"step": s, "status": "up to date"} for s in plan.up_to_date]
    for s in plan.steps:
        o = outcomes[f"{plan.scene.name}:{s}"]
        steps.append({"step": s, "status": o.status, "seconds": o.seconds, "worker": o.worker, "error": o.error,
                      "warnings": _step_warnings(o), "report": o.value})
    doc = {"scene": plan.scene.name, "input": str(plan.scene.source), "reader": plan.scene.reader or "raw product",
           "outputs": {k: str(v) for k, v in plan.outputs.items() if k != "report"}, "steps": steps}
    with atomic_path(plan.outputs["report"], ".json") as tmp, open(tmp, "w") as fh:
        json.dump(to_jsonable(doc), fh, indent=2)
        fh.write("\n")


def run(config: Config, provenance: Provenance | None = None, progress: Progress | None = None) -> BatchReport:
    """Process every scene of ``config.input`` (module docstring)."""
    from sarcli.parallel.graph import Task

    progress = progress or no_progress
    with using(provenance):
        t0 = time.perf_counter()
        src, out = Path(config.input).resolve(), Path(config.output).resolve()
        if not src.is_dir():
            raise ConfigError(f"input folder {config.input} does not exist")
        if out == src:
            raise ConfigError("the output folder is the input folder: give another one (products would be taken "
                              "for inputs)")
        if not out.parent.is_dir():
            raise ConfigError(f"output folder {out.parent} does not exist: create it first")
        if config.report is not None:
            _check_report(config.report)
        scenes, ignored, bad = discover(src)
        if not scenes and not bad:
            listed = "; ".join(f"{i['entry']} ({i['why']})" for i in ignored[:8])
            listed += "; ..." if len(ignored) > 8 else ""
            raise ConfigError(f"no raw products or sensor inputs in {config.input}"
                              + (f"; ignored: {listed}" if ignored else " (it is empty)"))
        out.mkdir(exist_ok=True)
        suffix = f" (sarcli batch {config.input} -o {config.output})"
        plans = [plan_scene(s, out, suffix, dict(config.focus), config.geotiff) for s in scenes]
        tasks: list[Task] = []
        for p in plans:
            prev: tuple[str, ...] = ()
            for step, (step_config, cmd) in p.steps.items():
                key = f"{p.scene.name}:{step}"
                fn, args = ((run_focus, (step_config, cmd, config.geotiff)) if step == "focus" else
                            (run_step, (step, step_config, cmd)))
                tasks.append(Task(key, fn, args, prev, label=step))
                prev = (key,)
        spec = config.cluster()
        where = "this process" if spec is None else spec.describe()
        log.info("batch: %d scene(s), %d task(s) on %s", len(scenes), len(tasks), where)
        outcomes = _execute(tasks, spec, config, progress) if tasks else {}
        failures = list(bad)
        counts = {"done": 0, "failed": 0, "skipped": 0, "up_to_date": 0}
        rows = []
        for p in plans:
            status = {s: "up to date" for s in p.up_to_date}
            warned: dict[str, int] = {}
            counts["up_to_date"] += len(p.up_to_date)
            for s in p.steps:
                o = outcomes[f"{p.scene.name}:{s}"]
                status[s] = o.status
                if _step_warnings(o):
                    warned[s] = len(_step_warnings(o))
                counts[o.status] += 1
                if o.status == "failed":
                    failures.append({"scene": p.scene.name, "step": s, "error": o.error})
            if p.steps:
                _write_scene_report(p, outcomes)
            rows.append({"scene": p.scene.name, "input": str(p.scene.source),
                         "steps": {s: status.get(s, "-") for s in STEPS if s in status}, "warnings": warned,
                         "report": str(p.outputs["report"]) if p.outputs["report"].exists() else None})
        return BatchReport(input=str(config.input), output=str(config.output), where=where, scenes=rows,
                           failures=failures, ignored=ignored, counts=counts, wall_s=time.perf_counter() - t0,
                           performance_report=None if config.report is None else str(config.report))


def _check_report(path: Path) -> None:
    if not Path(path).resolve().parent.is_dir():
        raise ConfigError(f"--report folder {Path(path).resolve().parent} does not exist")
    try:
        import bokeh  # noqa: F401 (Dask's performance report renders with bokeh)
    except ImportError:
        raise ConfigError("--report needs bokeh (pip install 'sarcli[report]')") from None


def _execute(tasks, spec, config: Config, progress: Progress) -> dict[str, Any]:
    from sarcli.parallel.graph import run_tasks

    if spec is None:
        return run_tasks(tasks, None, progress, config.retries)
    from sarcli.parallel.cluster import connect

    with connect(spec) as client:
        if config.report is None:
            return run_tasks(tasks, client, progress, config.retries)
        from distributed import performance_report

        with client.as_current(), performance_report(filename=os.fspath(config.report)):
            return run_tasks(tasks, client, progress, config.retries)
