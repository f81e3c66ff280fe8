"""The output-equals-input guard (workflows.base.refuse_overwriting_inputs) and durable atomic writes."""

from __future__ import annotations

import os

import numpy as np
import pytest

from sarcli.errors import ConfigError
from sarcli.io import atomic
from sarcli.io.h5common import atomic_h5, dataset
from sarcli.workflows.base import refuse_overwriting_inputs


@pytest.fixture
def inp(tmp_path):
    p = tmp_path / "raw.h5"
    p.write_bytes(b"measured once")
    return p


def test_distinct_outputs_pass(tmp_path, inp):
    refuse_overwriting_inputs([inp, None], [tmp_path / "slc.h5", None, tmp_path / "q.png"])


def test_same_path_refused(inp):
    with pytest.raises(ConfigError, match="is the input"):
        refuse_overwriting_inputs([inp], [inp])


def test_other_spelling_of_the_same_path_refused(tmp_path, inp, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    for spelling in ("raw.h5", "./raw.h5", "sub/../raw.h5", str(inp)):
        with pytest.raises(ConfigError, match="refusing to overwrite an input"):
            refuse_overwriting_inputs([inp], [spelling])


def test_symlink_to_the_input_refused(tmp_path, inp):
    link = tmp_path / "link.h5"
    link.symlink_to(inp)
    with pytest.raises(ConfigError, match="is the input"):
        refuse_overwriting_inputs([inp], [link])
    with pytest.raises(ConfigError, match="is the input"):  # and the other way round
        refuse_overwriting_inputs([link], [inp])


def test_symlinked_folder_refused(tmp_path, inp):
    (tmp_path / "alias").symlink_to(tmp_path, target_is_directory=True)
    with pytest.raises(ConfigError, match="is the input"):
        refuse_overwriting_inputs([inp], [tmp_path / "alias" / "raw.h5"])


def test_hard_link_refused(tmp_path, inp):
    other = tmp_path / "elsewhere.h5"
    os.link(inp, other)  # another name, the same inode: writing it would destroy the input
    with pytest.raises(ConfigError, match="is the input"):
        refuse_overwriting_inputs([inp], [other])


def test_same_output_twice_refused(tmp_path, inp):
    with pytest.raises(ConfigError, match="are the same file"):
        refuse_overwriting_inputs([inp], [tmp_path / "a.tif", tmp_path / "a.tif"])
    link = tmp_path / "b.tif"
    link.symlink_to(tmp_path / "a.tif")  # dangling until written: still the same file
    with pytest.raises(ConfigError, match="are the same file"):
        refuse_overwriting_inputs([inp], [tmp_path / "a.tif", link])


def test_non_existing_outputs_and_inputs(tmp_path):
    # neither exists yet: compared by real path only
    refuse_overwriting_inputs([tmp_path / "missing_in.h5"], [tmp_path / "out.h5"])
    with pytest.raises(ConfigError, match="is the input"):
        refuse_overwriting_inputs([tmp_path / "missing_in.h5"], [tmp_path / "missing_in.h5"])


def test_input_given_twice_is_fine(tmp_path, inp):
    refuse_overwriting_inputs([inp, inp], [tmp_path / "out.h5"])


def test_message_is_one_line_naming_both(tmp_path, inp):
    with pytest.raises(ConfigError) as e:
        refuse_overwriting_inputs([inp], [tmp_path / "." / "raw.h5"])
    msg = str(e.value)
    assert "\n" not in msg and str(inp) in msg and "raw.h5" in msg


def test_atomic_path_fsyncs_file_before_rename_and_folder_after(tmp_path, monkeypatch):
    """Durability order: data of the temporary file on disk, then the rename, then the folder entry."""
    events = []
    real_fsync, real_replace = os.fsync, os.replace

    def fsync(fd):
        events.append(("fsync", os.path.realpath(f"/proc/self/fd/{fd}")))
        real_fsync(fd)

    def replace(a, b):
        events.append(("replace", os.path.realpath(b)))
        real_replace(a, b)

    monkeypatch.setattr(atomic.os, "fsync", fsync)
    monkeypatch.setattr(atomic.os, "replace", replace)
    target = tmp_path / "p.h5"
    with atomic_h5(target, "test", "1") as f:
        dataset(f, "x", np.arange(3))
        tmp_name = f.filename
    assert [e[0] for e in events] == ["fsync", "replace", "fsync"]
    assert events[0][1] == os.path.realpath(tmp_name)  # the finished temporary file
    assert events[1][1] == str(target.resolve())
    assert events[2][1] == str(tmp_path.resolve())  # its folder, after the rename


def test_atomic_path_failure_fsyncs_nothing_and_leaves_nothing(tmp_path, monkeypatch):
    calls = []
    monkeypatch.setattr(atomic.os, "fsync", lambda fd: calls.append(fd))
    with pytest.raises(RuntimeError), atomic.atomic_path(tmp_path / "x.tif") as tmp:
        with open(tmp, "wb") as fh:
            fh.write(b"half")
        raise RuntimeError("crash")
    assert calls == [] and list(tmp_path.iterdir()) == []
