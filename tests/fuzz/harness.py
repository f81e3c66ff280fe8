"""Fuzz harness: corrupt a copy of a real product, run a sarcli command on it, check the promises.

The promises (docs/products.md, "The fuzz suite"), checked for every case:

- the command exits 0 and its products are plausible (they pass their own reader's validation, every
  number finite), or it exits non-zero with exactly one ``sarcli: error:`` line on stderr;
- never a traceback (an exception escaping the CLI), never a hang (a soft timeout per case raised in
  Python, and a hard watchdog that kills the process with a traceback dump if C code hangs);
- the input bytes are unchanged (SHA-256 of every input file before and after);
- no partial output: after a failure the output folder is empty, after a success it holds no
  temporary file.

A corruption is an immutable, printable value (its ``repr`` reproduces the case), drawn by Hypothesis
from a catalogue of what the pristine product holds: attributes, datasets, groups, bytes.
"""

from __future__ import annotations

import contextlib
import dataclasses
import faulthandler
import functools
import hashlib
import json
import math
import os
import shutil
import signal
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from hypothesis import strategies as st
from typer.testing import CliRunner

#: Case folders live in memory where the machine has a tmpfs (thousands of small files a run).
SCRATCH = "/dev/shm" if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK) else None
SOFT_TIMEOUT_S = 30.0  # a tiny case takes ~0.1 s; this is a hang
HARD_TIMEOUT_S = 120.0  # C code that never returns: the watchdog kills the process (traceback dump)
BAD_UTF8 = b"bad\xff\xfeutf8"

# ----------------------------------------------------------------------------------------------------
# corruptions


@dataclasses.dataclass(frozen=True)
class AttrEdit:
    """Delete (value None) or overwrite an attribute of the object at ``obj``."""

    obj: str
    name: str
    value: Any

    def apply(self, root: Path, target: str) -> None:
        with h5py.File(root / target, "r+") as f:
            o = f[self.obj]
            if isinstance(self.name, bytes):  # a new attribute whose name is not UTF-8 (h5py's API refuses it)
                h5py.h5a.create(o.id, self.name, h5py.h5t.NATIVE_DOUBLE, h5py.h5s.create(h5py.h5s.SCALAR)).write(
                    np.array(1.0))
            elif self.value is None:
                del o.attrs[self.name]
            elif isinstance(self.value, tuple) and self.value[0] == "scale":
                o.attrs[self.name] = o.attrs[self.name] * self.value[1]
            elif self.value == BAD_UTF8:
                o.attrs.create(self.name, BAD_UTF8, dtype=h5py.string_dtype("utf-8"))
            else:
                o.attrs[self.name] = self.value


@dataclasses.dataclass(frozen=True)
class DataEdit:
    """Change a dataset: delete, empty, shorten, NaN/inf/huge at an element, zeros, reverse, constant,
    scalar, scale, wrong dtype (int, text, float from complex), replace by a group, lengthen."""

    path: str
    op: str
    index: int = 0
    factor: float = 1.0

    def apply(self, root: Path, target: str) -> None:
        with h5py.File(root / target, "r+") as f:
            ds = f[self.path]
            a = ds[()]
            op = self.op
            if op == "delete":
                del f[self.path]
                return
            if op == "to_group":
                del f[self.path]
                f.create_group(self.path)
                return
            a = np.asarray(a)
            if op == "empty":
                a = a[:0] if a.ndim else np.zeros(0, a.dtype)
            elif op == "shorten":
                a = a[: max(a.shape[0] - 1 - self.index % 3, 0)] if a.ndim else a
            elif op == "lengthen":
                a = np.concatenate([a, a[-1:]]) if a.ndim and a.shape[0] else a
            elif op in ("nan", "inf", "neg_inf", "huge") and a.size and a.dtype.kind in "fc":
                a = a.copy()
                a.flat[self.index % a.size] = {"nan": np.nan, "inf": np.inf, "neg_inf": -np.inf, "huge": 1e300}[op]
            elif op in ("nan", "inf", "neg_inf", "huge") and a.size and a.dtype.kind in "iu":
                a = a.copy()
                a.flat[self.index % a.size] = np.iinfo(a.dtype).max if op != "neg_inf" else np.iinfo(a.dtype).min
            elif op == "zeros":
                a = np.zeros_like(a)
            elif op == "reverse" and a.ndim:
                a = a[::-1].copy()
            elif op == "constant" and a.size and a.dtype.names is None:
                a = np.full_like(a, a.flat[0])
            elif op == "scalar":
                a = a.flat[0] if a.size else np.float64(0.0)
            elif op == "scale" and a.dtype.kind in "fc":
                a = a * self.factor
            elif op == "add" and a.dtype.kind in "fc":
                a = a + self.factor
            elif op == "to_int" and a.dtype.kind in "fc":
                a = np.real(a).astype(np.int32) if np.all(np.isfinite(np.real(a))) else np.zeros(a.shape, np.int32)
            elif op == "to_str" and a.dtype.names is None:
                a = np.char.encode(a.astype(str), "ascii") if a.dtype.kind != "O" else np.zeros(a.shape)
            elif op == "to_float" and a.dtype.kind == "c":
                a = a.real.astype(np.float32)
            elif op == "to_complex" and a.dtype.kind in "fiu":
                a = a.astype(np.complex64)
            attrs = dict(ds.attrs)
            del f[self.path]
            new = f.create_dataset(self.path, data=a)
            for k, v in attrs.items():
                new.attrs[k] = v


@dataclasses.dataclass(frozen=True)
class GroupEdit:
    """Delete a group or replace it by a dataset."""

    path: str
    op: str

    def apply(self, root: Path, target: str) -> None:
        with h5py.File(root / target, "r+") as f:
            del f[self.path]
            if self.op == "to_dataset":
                f[self.path] = np.arange(3.0)


@dataclasses.dataclass(frozen=True)
class ByteEdit:
    """File-level damage of ``file`` (relative to the case folder): truncate at a fraction, XOR bytes at
    offsets, zero a run, append garbage, empty the file, delete it."""

    file: str
    op: str
    fraction: float = 0.5
    offsets: tuple[int, ...] = ()
    xor: int = 0xFF

    def apply(self, root: Path, target: str) -> None:
        p = root / self.file
        data = bytearray(p.read_bytes())
        n = len(data)
        if self.op == "delete":
            p.unlink()
            return
        if self.op == "truncate":
            data = data[: int(n * self.fraction)]
        elif self.op == "empty":
            data = bytearray()
        elif self.op == "flip":
            for o in self.offsets:
                data[o % n] ^= self.xor
        elif self.op == "zero_run":
            a = int(n * self.fraction)
            data[a:a + 64] = bytes(len(data[a:a + 64]))
        elif self.op == "append":
            data += bytes((o * 37 + self.xor) % 256 for o in range(97))
        p.write_bytes(bytes(data))


@dataclasses.dataclass(frozen=True)
class TextEdit:
    """Replace the text ``old`` (which must occur) by ``new`` in the text file ``file`` (a scene file)."""

    file: str
    old: str
    new: str

    def apply(self, root: Path, target: str) -> None:
        p = root / self.file
        text = p.read_text()
        assert self.old in text, f"{self.file} has no {self.old!r}"
        p.write_text(text.replace(self.old, self.new))


@dataclasses.dataclass(frozen=True)
class NoEdit:
    """The pristine product itself (a case whose hostile part is the command line)."""

    def apply(self, root: Path, target: str) -> None:
        return None


Corruption = AttrEdit | DataEdit | GroupEdit | ByteEdit | TextEdit | NoEdit


@dataclasses.dataclass(frozen=True)
class Catalogue:
    """What a pristine HDF5 product holds: (object, attribute, kind), (dataset, dtype kind, size), groups."""

    attrs: tuple[tuple[str, str, str], ...]
    datasets: tuple[tuple[str, str, int], ...]
    groups: tuple[str, ...]
    size: int


def catalogue(path: Path) -> Catalogue:
    attrs, datasets, groups = [], [], []

    def attr_kinds(name: str, obj: Any) -> None:
        for k, v in obj.attrs.items():
            kind = "text" if isinstance(v, str | bytes) else "num" if np.ndim(v) == 0 else "array"
            attrs.append((name, k, kind))

    with h5py.File(path) as f:
        attr_kinds("/", f)

        def visit(name: str, obj: Any) -> None:
            attr_kinds("/" + name, obj)
            if isinstance(obj, h5py.Dataset):
                datasets.append(("/" + name, obj.dtype.kind if obj.dtype.names is None else "V", int(obj.size)))
            else:
                groups.append("/" + name)
        f.visititems(visit)
    return Catalogue(tuple(attrs), tuple(datasets), tuple(groups), path.stat().st_size)


_ATTR_VALUES = (None, "garbage", "1e3", "", BAD_UTF8, 0, -1, 0.0, -1.0, math.nan, math.inf, -math.inf, 1e300, 1e-9,
                (1.0, 2.0, 3.0), True, 2**40)
_DATA_OPS = ("delete", "empty", "shorten", "lengthen", "nan", "inf", "neg_inf", "huge", "zeros", "reverse",
             "constant", "scalar", "scale", "to_int", "to_str", "to_float", "to_complex", "to_group")
_FACTORS = (-1.0, 0.0, 0.5, 2.0, 1e3, 1e-3, 1e12)


def _attr_values(kind: str) -> st.SearchStrategy:
    vals = st.sampled_from(_ATTR_VALUES)
    if kind == "num":
        return st.one_of(vals, st.sampled_from(_FACTORS).map(lambda k: ("scale", k)))
    return vals


def h5_corruptions(cat: Catalogue, file: str, where: Callable[[str], bool] = lambda path: True,
                   file_level: bool = True) -> st.SearchStrategy[Corruption]:
    """Every kind of damage to the HDF5 product ``file`` of the case folder: to the objects whose path
    satisfies ``where``, and (``file_level``) to its bytes."""
    parts = []
    attrs = [a for a in cat.attrs if where(a[0])]
    datasets = [d for d in cat.datasets if where(d[0])]
    groups = [g for g in cat.groups if where(g)]
    if attrs:
        parts.append(st.sampled_from(attrs).flatmap(
            lambda a: _attr_values(a[2]).map(lambda v: AttrEdit(a[0], a[1], v))))
        objects = sorted({a[0] for a in attrs})
        parts.append(st.builds(AttrEdit, st.sampled_from(objects), st.just(BAD_UTF8), st.just(1.0)))
    if datasets:
        parts.append(st.builds(lambda d, op, i, k: DataEdit(d[0], op, i, k), st.sampled_from(datasets),
                               st.sampled_from(_DATA_OPS), st.integers(0, 10**6), st.sampled_from(_FACTORS)))
    if groups:
        parts.append(st.builds(GroupEdit, st.sampled_from(groups), st.sampled_from(("delete", "to_dataset"))))
    if file_level:
        parts.append(byte_corruptions(file, cat.size))
    return st.one_of(*parts)


def byte_corruptions(file: str, size: int) -> st.SearchStrategy[ByteEdit]:
    """Truncation, bit damage (biased to the first 4 KiB where the metadata lives), zeroed runs, garbage."""
    offset = st.one_of(st.integers(0, min(size, 4096) - 1), st.integers(0, size - 1))
    return st.one_of(
        st.builds(ByteEdit, st.just(file), st.just("truncate"), st.floats(0.0, 0.999)),
        st.builds(ByteEdit, st.just(file), st.just("flip"), st.just(0.5),
                  st.lists(offset, min_size=1, max_size=16).map(tuple), st.integers(1, 255)),
        st.builds(ByteEdit, st.just(file), st.just("zero_run"), st.floats(0.0, 0.999)),
        st.builds(ByteEdit, st.just(file), st.sampled_from(("append", "empty", "delete"))),
    )


# ----------------------------------------------------------------------------------------------------
# running a case


@dataclasses.dataclass
class Outcome:
    case: str
    exit_code: int
    stdout: str
    stderr: str
    outputs: list[Path]


class CaseTimeout(BaseException):
    """A case ran longer than SOFT_TIMEOUT_S (a hang): raised in the main thread by SIGALRM."""


@contextlib.contextmanager
def _deadline() -> Iterator[None]:
    def on_alarm(signum, frame):
        raise CaseTimeout(f"no result after {SOFT_TIMEOUT_S} s")

    old = signal.signal(signal.SIGALRM, on_alarm)
    signal.setitimer(signal.ITIMER_REAL, SOFT_TIMEOUT_S)
    faulthandler.dump_traceback_later(HARD_TIMEOUT_S, exit=True, file=sys.__stderr__)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)
        faulthandler.cancel_dump_traceback_later()


@contextlib.contextmanager
def _cached_command() -> Iterator[None]:
    """Typer builds the click command tree on every invoke (~0.1 s); build it once per process."""
    import typer.testing

    build = typer.testing._get_command
    if not hasattr(build, "cache_info"):
        typer.testing._get_command = functools.lru_cache(maxsize=4)(build)
    yield


def _hashes(paths: list[Path]) -> dict[str, str]:
    out = {}
    for p in paths:
        for f in sorted(p.rglob("*")) if p.is_dir() else [p]:
            if f.is_file():
                out[str(f)] = hashlib.sha256(f.read_bytes()).hexdigest()
    return out


def run_case(pristine: dict[str, Path], product: str, command: tuple[str, ...], corruption: Corruption,
             check_output: Callable[[str, Path, Outcome], None]) -> Outcome:
    """Copy the pristine inputs into a fresh folder, damage ``product``, run ``command`` (``{IN}`` is the
    damaged product, ``{OUT}``/``{OUT2}`` outputs in an empty folder, ``{NAME}`` another pristine input)
    and assert every promise (module docstring). ``check_output(kind, path, outcome)`` checks each
    product a successful command wrote."""
    from sarcli.cli.app import app

    with tempfile.TemporaryDirectory(prefix="sarcli-fuzz-", dir=SCRATCH) as tmp:
        tmp = Path(tmp)
        inputs = tmp / "in"
        out = tmp / "out"
        inputs.mkdir()
        out.mkdir()
        names = {}
        for key, src in pristine.items():  # the damaged product (a copy) and the other inputs the command
            dst = inputs / src.name           # names (hard links: their hashes are checked like the copy's)
            if key == product:
                (shutil.copytree if src.is_dir() else shutil.copyfile)(src, dst)
            elif f"{{{key}}}" in command:
                os.link(src, dst)
            else:
                continue
            names[key] = dst
        corruption.apply(inputs, names[product].name)
        before = _hashes([inputs])
        repl = {"{IN}": str(names[product]), "{OUT}": str(out / "product.h5"), "{OUT_TIF}": str(out / "image.tif"),
                "{OUT_PNG}": str(out / "quicklook.png")}
        repl.update({f"{{{k}}}": str(v) for k, v in names.items()})
        args = [repl.get(a, a) for a in command]
        case = f"{product} <- {corruption!r}; sarcli {' '.join(command)}"
        with _deadline(), _cached_command():
            try:
                r = CliRunner().invoke(app, args, catch_exceptions=True)
            except CaseTimeout as e:
                raise AssertionError(f"HANG ({e}): {case}") from None
        outcome = Outcome(case, r.exit_code, r.stdout, r.stderr, sorted(out.iterdir()))
        if r.exception is not None and not isinstance(r.exception, SystemExit):
            import traceback

            tb = "".join(traceback.format_exception(r.exception)).strip().splitlines()
            raise AssertionError(f"TRACEBACK {type(r.exception).__name__}: {r.exception}\n  case: {case}\n  "
                                 + "\n  ".join(tb[-8:]))
        assert "Traceback" not in r.stderr, f"traceback on stderr: {case}\n{r.stderr[-2000:]}"
        assert _hashes([inputs]) == before, f"INPUT MODIFIED: {case}"
        leftovers = [p.name for p in outcome.outputs if p.name.startswith(".")]
        assert not leftovers, f"temporary files left behind {leftovers}: {case}"
        if r.exit_code == 0:
            from sarcli.errors import ProductError

            for p in outcome.outputs:
                try:
                    check_output(command[0], p, outcome)
                except ProductError as e:
                    raise AssertionError(f"IMPLAUSIBLE PRODUCT with exit 0: {e}\n  case: {case}") from None
        else:
            errors = [ln for ln in r.stderr.splitlines() if ln.startswith("sarcli: error:")]
            assert len(errors) == 1, f"exit {r.exit_code} with {len(errors)} error lines: {case}\n{r.stderr[-2000:]}"
            assert r.exit_code in (1, 2), f"exit {r.exit_code}: {case}\n{r.stderr}"
            assert not outcome.outputs, f"PARTIAL OUTPUT {[p.name for p in outcome.outputs]} after exit " \
                                        f"{r.exit_code}: {case}\n{errors[0]}"
        return outcome


def _finite_json(obj: Any, where: str) -> None:
    if isinstance(obj, dict):
        for k, v in obj.items():
            _finite_json(v, f"{where}.{k}")
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            _finite_json(v, f"{where}[{i}]")
    elif isinstance(obj, float):
        assert math.isfinite(obj), f"non-finite {where} = {obj}"


def check_output(kind: str, path: Path, outcome: Outcome) -> None:
    """A successful command's product is plausible: it passes its reader's validation, numbers are finite."""
    from sarcli.io.h5common import open_product

    suffix = path.suffix
    if path.is_dir():  # a CEOS product folder
        assert any(p.stat().st_size > 0 for p in path.iterdir()), f"empty product folder: {outcome.case}"
    elif suffix == ".h5":
        with open_product(path) as f:
            ptype = f.attrs["product_type"]
        if ptype == "raw":
            from sarcli.io.raw import read_raw

            read_raw(path)
        elif ptype == "slc":
            from sarcli.io.slc import read_slc

            read_slc(path)
        elif ptype == "doppler":
            from sarcli.io.doppler_product import read_doppler

            m = read_doppler(path)
            r0 = float(np.median(m.blocks["range_m"])) if "range_m" in m.blocks else 1e6
            t0 = float(np.median(m.blocks["azimuth_time_s"])) if "azimuth_time_s" in m.blocks else 0.0
            fdc, fr = float(m.fdc(r0, t0)), float(m.fr(r0, t0))
            assert math.isfinite(fdc) and math.isfinite(fr) and fr < 0, f"implausible Doppler {fdc}, {fr}: " \
                                                                         f"{outcome.case}"
            assert math.isfinite(m.prf_hz) and m.prf_hz > 0
            if m.summary is not None:  # physics, not only the type: the centroid within 2 V / lam of the
                # platform the product's own effective velocity implies, the rate negative (plausible.py)
                v = math.sqrt(-fr * m.wavelength_m * r0 / 2.0)
                assert abs(fdc) <= 2.0 * 1.2e4 / m.wavelength_m and v <= 1.2e4, \
                    f"implausible Doppler fdc {fdc:.6g} Hz, V {v:.6g} m/s: {outcome.case}"
        elif ptype == "gbsar_scan":
            from sarcli.io.scan import read_scan

            read_scan(path)
        elif ptype == "gbsar_image":
            from sarcli.io.gbsar_image import read_gbsar_image

            read_gbsar_image(path)
        elif ptype == "gbsar_interferogram":
            from sarcli.io.interferogram import read_interferogram

            read_interferogram(path)
        else:
            raise AssertionError(f"unexpected product type {ptype}: {outcome.case}")
    elif suffix in (".tif", ".png"):
        assert path.stat().st_size > 0

    if "--json" in outcome.case.split("sarcli ", 1)[1].split():
        _finite_json(json.loads(outcome.stdout), "json")
    else:
        assert outcome.stdout.strip() or outcome.outputs, f"exit 0 without output: {outcome.case}"


def fuzz_settings(examples: int) -> Any:
    """Hypothesis settings of a fuzz test: ``examples`` cases (``SARCLI_FUZZ_EXAMPLES`` overrides it), no
    deadline (a case's time is bounded by the harness's timeouts), no example database."""
    from hypothesis import HealthCheck, settings

    n = int(os.environ.get("SARCLI_FUZZ_EXAMPLES", examples))
    return settings(max_examples=n, deadline=None, database=None, suppress_health_check=list(HealthCheck))


# ----------------------------------------------------------------------------------------------------
# what is fuzzed: (damaged product, command) pairs. ``{IN}`` is the damaged product, ``{raw}`` etc. a
# pristine one, ``{OUT}`` an output.

FDC_FR = ("--fdc", "-6590", "--fr", "-1787")
COMMANDS: dict[str, list[tuple[str, ...]]] = {
    "raw": [("doppler", "{IN}", "-o", "{OUT}"), ("focus", "{IN}", "-o", "{OUT}"), ("orbit", "info", "{IN}"),
            ("info", "{IN}"), ("info", "{IN}", "--json"), ("focus", "{IN}", *FDC_FR, "-o", "{OUT}"),
            ("focus", "{IN}", "--doppler", "{doppler}", "-o", "{OUT}")],
    "doppler": [("focus", "{raw}", "--doppler", "{IN}", "-o", "{OUT}"), ("info", "{IN}")],
    "slc": [("quality", "{IN}"), ("quality", "{IN}", "--json"), ("info", "{IN}", "--json")],
    "scan": [("gbsar", "focus", "{IN}", "-o", "{OUT}"), ("gbsar", "interfere", "{IN}", "{scan2}", "-o", "{OUT}"),
             ("info", "{IN}")],
    "image": [("gbsar", "interfere", "{IN}", "{image2}", "-o", "{OUT}"),
              ("gbsar", "polarimetry", "{IN}", "--png", "{OUT_PNG}"), ("info", "{IN}")],
    "ceos": [("ingest", "{IN}", "-o", "{OUT}")],
}
#: Costly pairs (about 1 s a case): the exploration run only.
EXPLORE_ONLY: dict[str, list[tuple[str, ...]]] = {
    "raw": [("focus", "{IN}", *FDC_FR, "-o", "{OUT}", "--geotiff", "{OUT_TIF}", "--quicklook", "{OUT_PNG}")],
}
def corruptions(pristine: Any, product: str, where: Callable[[str], bool] = lambda path: True,
                file_level: bool = True) -> st.SearchStrategy[Corruption]:
    """Every kind of damage to a pristine product (HDF5: to the objects ``where`` selects, and to its
    bytes if ``file_level``) or to any file of the CEOS folder."""
    if product == "ceos":
        folder = pristine.paths["ceos"]
        return st.one_of(*[byte_corruptions(f"ceos/{f.name}", f.stat().st_size) for f in sorted(folder.iterdir())])
    return h5_corruptions(pristine.catalogues[product], pristine.paths[product].name, where, file_level)


def fuzz(pristine: Any, product: str, commands: list[tuple[str, ...]], data: Any,
         where: Callable[[str], bool] = lambda path: True, file_level: bool = True) -> Outcome:
    """One Hypothesis example: draw a command and a corruption (:func:`corruptions`), run the case."""
    command = data.draw(st.sampled_from(commands), label="command")
    corruption = data.draw(corruptions(pristine, product, where, file_level), label="corruption")
    return run_case(pristine.paths, product, command, corruption, check_output)


def run_reader_case(src: Path, corruption: Corruption, reader: Callable[[Path], Any]) -> Any:
    """Damage a copy of ``src`` and read it: the reader returns a value or raises one ProductError line;
    any other exception escapes (the test fails), a hang is caught, the file's bytes are unchanged."""
    from sarcli.errors import ProductError

    with tempfile.TemporaryDirectory(prefix="sarcli-fuzz-", dir=SCRATCH) as tmp:
        path = Path(tmp) / src.name
        shutil.copyfile(src, path)
        corruption.apply(Path(tmp), src.name)
        before = _hashes([Path(tmp)])
        with _deadline():
            try:
                value = reader(path)
            except ProductError as e:
                assert "\n" not in str(e), f"multi-line error: {corruption!r}"
                value = None
            except CaseTimeout as e:
                raise AssertionError(f"HANG ({e}) reading {src.name} <- {corruption!r}") from None
        assert _hashes([Path(tmp)]) == before, f"INPUT MODIFIED reading {src.name} <- {corruption!r}"
        return value
