"""Explicit fuzz cases, each a defect the fuzzer once found outside the product readers, kept
as regressions with the file that had it; and the fuzz over the Doppler and SLC products (read by
focus, quality and info). Same promises as every fuzz test (tests/fuzz/harness.py)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.fuzz.harness import (
    BAD_UTF8,
    COMMANDS,
    FDC_FR,
    AttrEdit,
    DataEdit,
    GroupEdit,
    check_output,
    fuzz,
    fuzz_settings,
    run_case,
)

KNOWN = [
    # (id, damaged product, corruption, command, what happened before the fix, where it was)
    ("info-no-radar", "raw", GroupEdit("/radar", "delete"), ("info", "{IN}"),
     "TypeError: unsupported format string passed to NoneType.__format__", "sarcli/cli/commands/info.py _human"),
    ("info-no-azimuth-time", "raw", DataEdit("/azimuth_time", "delete"), ("info", "{IN}"),
     "TypeError: unsupported format string passed to NoneType.__format__", "sarcli/cli/commands/info.py _human"),
    ("info-units-array", "raw", AttrEdit("/orbit/time", "units", (1.0, 2.0, 3.0)), ("info", "{IN}"),
     "ValueError: truth value of an array is ambiguous", "sarcli/cli/commands/info.py summarize (units == 's')"),
    ("info-slc-prf-bad-utf8", "slc", AttrEdit("/", "prf_hz", BAD_UTF8), ("info", "{IN}", "--json"),
     "ValueError: could not convert string to float", "sarcli/cli/commands/info.py _slc_summary (_num)"),
    ("info-scan-frequency-text", "scan", DataEdit("/frequency", "to_str"), ("info", "{IN}"),
     "UFuncTypeError: ufunc 'minimum' on S12", "sarcli/cli/commands/info.py _scan_summary"),
    ("doppler-prf-empty-text", "doppler", AttrEdit("/", "prf_hz", ""), ("focus", "{raw}", "--doppler", "{IN}", "-o",
                                                                          "{OUT}"),
     "ValueError: could not convert string to float: ''", "sarcli/io/doppler_product.py read_doppler"),
    ("quality-truth-complex", "slc", DataEdit("/truth/reference_height_m", "to_complex"), ("quality", "{IN}"),
     "TypeError: float() argument must be ... not 'complex'", "sarcli/focus/quality.py (reads truth unchecked)"),
    ("focus-stream-nan-echo", "raw", DataEdit("/echo", "nan", 1000), ("focus", "{IN}", *FDC_FR, "-o", "{OUT}"),
     "exit 0 with an all-NaN SLC (the streamed path reads /echo directly, not read_raw_echo_block)",
     "sarcli/cli/commands/focus.py (streaming branch)"),
    ("focus-stream-inf-echo-doppler", "raw", DataEdit("/echo", "inf", 1000),
     ("focus", "{IN}", "--doppler", "{doppler}", "-o", "{OUT}"),
     "exit 0 with an all-NaN SLC", "sarcli/cli/commands/focus.py (streaming branch)"),
    ("focus-stream-partial-output", "raw", DataEdit("/echo", "huge", 44805),
     ("focus", "{IN}", *FDC_FR, "-o", "{OUT}", "--geotiff", "{OUT_TIF}", "--quicklook", "{OUT_PNG}"),
     "exit 1 (read_slc refuses the NaN image it just wrote) and the SLC is left behind",
     "sarcli/cli/commands/focus.py (outputs written one after the other, no rollback)"),
    ("doppler-truth-height-empty", "raw", DataEdit("/truth/reference_height_m", "empty"), ("doppler", "{IN}", "-o",
                                                                                            "{OUT}"),
     "TypeError: only 0-dimensional arrays can be converted to Python scalars",
     "sarcli/doppler/api.py estimate_doppler (reads truth)"),
    ("focus-truth-height-complex", "raw", DataEdit("/truth/reference_height_m", "to_complex"),
     ("focus", "{IN}", *FDC_FR, "-o", "{OUT}"), "TypeError: float() argument must be ... not 'complex'",
     "sarcli/focus/rda.py _reference_height (reads truth)"),
    ("doppler-poly-attr-array", "doppler", AttrEdit("/fdc_poly", "y0", (1.0, 2.0, 3.0)),
     ("focus", "{raw}", "--doppler", "{IN}", "-o", "{OUT}"),
     "TypeError: only 0-dimensional arrays can be converted", "sarcli/io/doppler_product.py _read_poly"),
    ("quality-truth-targets-scalar", "slc", DataEdit("/truth/targets", "scalar"), ("quality", "{IN}", "--json"),
     "TypeError: 'numpy.float64' object is not iterable", "sarcli/focus/quality.py (reads truth unchecked)"),
    ("info-wavelength-empty-text", "raw", AttrEdit("/radar", "wavelength_m", ""), ("info", "{IN}"),
     "ValueError: Unknown format code 'f' for object of type 'str'", "sarcli/cli/commands/info.py _human"),
    ("info-no-echo", "raw", DataEdit("/echo", "delete"), ("info", "{IN}"), "KeyError: 'azimuth_start_utc'",
     "sarcli/cli/commands/info.py _human"),
    ("info-scan-epoch-number", "scan", AttrEdit("/", "epoch_utc", math.nan), ("info", "{IN}"),
     "AttributeError: 'numpy.float64' object has no attribute 'strip'", "sarcli/cli/commands/info.py _utc"),
    ("info-scan-n-planned-array", "scan", AttrEdit("/", "n_planned", (1.0, 2.0, 3.0)), ("info", "{IN}"),
     "TypeError: only 0-dimensional arrays can be converted", "sarcli/cli/commands/info.py _int"),
    ("info-scan-stop-time-inf", "scan", DataEdit("/stop_time", "neg_inf", 3), ("info", "{IN}"),
     "OverflowError: cannot convert float infinity to integer", "sarcli/cli/commands/info.py _utc/_time_span"),
    ("info-attribute-name-not-utf8", "doppler", AttrEdit("/", BAD_UTF8, 1.0), ("info", "{IN}"),
     "TypeError: '<' not supported between bytes and str (an attribute name that is not UTF-8)",
     "sarcli/cli/commands/info.py _attrs (sorted(obj.attrs))"),
]


@pytest.mark.parametrize("product, corruption, command, today, owner", [k[1:] for k in KNOWN],
                         ids=[k[0] for k in KNOWN])
def test_known_case(pristine, product, corruption, command, today, owner):
    run_case(pristine.paths, product, command, corruption, check_output)


@pytest.mark.parametrize("product", ["doppler", "slc"])
def test_fuzz_products(pristine, product):
    @fuzz_settings(60)
    @given(data=st.data())
    def damaged(data):
        fuzz(pristine, product, COMMANDS[product], data)

    damaged()


WRITERS = [  # (input, command whose {SELF} output names the input file itself, that file within a folder)
    ("raw", ("focus", "{IN}", *FDC_FR, "-o", "{SELF}"), ""),
    ("raw", ("doppler", "{IN}", "-o", "{SELF}"), ""),
    ("raw", ("focus", "{IN}", *FDC_FR, "-o", "{OUT}", "--quicklook", "{SELF}"), ""),
    ("scan", ("gbsar", "focus", "{IN}", "-o", "{SELF}"), ""),
    ("image", ("gbsar", "interfere", "{IN}", "{image2}", "-o", "{SELF}"), ""),
    ("ceos", ("ingest", "{IN}", "-o", "{SELF}"), "DAT_01.001"),
]


@pytest.mark.parametrize("product, command, member", WRITERS,
                         ids=[f"{p}-{c[0]}-{i}" for i, (p, c, _) in enumerate(WRITERS)])
@pytest.mark.parametrize("alias", ["same", "hardlink"])
def test_output_equal_to_an_input_is_refused(pristine, tmp_path, product, command, member, alias):
    """An output naming an input (or a hard link to it) is refused before any work (a usage
    error, exit 2), the input intact."""
    import hashlib
    import os
    import shutil

    from tests.conftest import run_cli

    src = pristine.paths[product]
    inp = tmp_path / src.name
    (shutil.copytree if src.is_dir() else shutil.copyfile)(src, inp)
    victim = inp / member if member else inp
    if alias == "hardlink":
        os.link(victim, tmp_path / "alias")
        victim = tmp_path / "alias"
    files = sorted(inp.iterdir()) if inp.is_dir() else [inp]
    before = [hashlib.sha256(p.read_bytes()).hexdigest() for p in files]
    names = {"{IN}": inp, "{SELF}": victim, "{OUT}": tmp_path / "o.h5",
             **{f"{{{k}}}": v for k, v in pristine.paths.items()}}
    r = run_cli(*[str(names.get(a, a)) for a in command])
    assert r.exit_code == 2 and r.stderr.count("sarcli: error:") == 1, r.stderr
    assert [hashlib.sha256(p.read_bytes()).hexdigest() for p in files] == before
