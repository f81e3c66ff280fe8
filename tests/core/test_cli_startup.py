"""Start-up cost of a command: the root group lists the commands from a table and imports a command's
module only when that command runs (``sarcli --help`` imports none); the numba cache folder."""

from __future__ import annotations

import os
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

import sarcli.cli.commands as commands_pkg
from sarcli.cli.app import COMMANDS, load_command

HEAVY = ("numpy", "h5py", "scipy", "numba", "rasterio", "matplotlib", "pydantic")


def _modules_after(*argv: str) -> set[str]:
    """The modules a fresh interpreter has imported after running ``sarcli ARGV``."""
    code = ("import sys\nfrom sarcli.cli.app import main\nsys.argv = ['sarcli', *sys.argv[1:]]\n"
            "try:\n    main()\nexcept SystemExit:\n    pass\nprint('\\n'.join(sys.modules), file=sys.stderr)")
    r = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True)
    return set(r.stderr.split())


def test_every_command_module_is_in_the_table():
    listed = {m for mods, _ in COMMANDS.values() for m in mods}
    found = {m.name for m in pkgutil.iter_modules(commands_pkg.__path__)}
    assert found == listed, f"add to sarcli.cli.app.COMMANDS: {sorted(found - listed)}; gone: {sorted(listed - found)}"


@pytest.mark.parametrize("name", list(COMMANDS))
def test_listed_help_is_the_commands_own_first_paragraph(name):
    help_text = load_command(name).help or ""
    first = " ".join(help_text.split("\n\n")[0].split())
    assert COMMANDS[name][1] == first


def test_help_lists_every_command_in_table_order(cli):
    out = cli("--help").stdout
    listed = [line.split()[0] for line in out.split("Commands:")[1].splitlines() if line.strip()]
    assert listed == list(COMMANDS)


def test_root_help_imports_no_command_module_and_nothing_heavy():
    mods = _modules_after("--help")
    assert "sarcli.cli.app" in mods
    assert not {m for m in mods if m.startswith("sarcli.cli.commands.")}
    assert not {m.split(".")[0] for m in mods} & set(HEAVY)


def test_a_command_imports_only_its_own_module():
    mods = _modules_after("design", "--help")
    assert {m for m in mods if m.startswith("sarcli.cli.commands.")} == {"sarcli.cli.commands.design"}
    assert "pydantic" not in mods  # typer >= 0.29 validates every option through pydantic (pinned below)


def test_gbsar_group_loads_both_of_its_modules(cli):
    r = cli("gbsar", "--help")
    assert r.exit_code == 0
    for sub in ("simulate", "focus", "scan", "repeat"):
        assert f"  {sub} " in r.stdout


def test_unknown_command_is_a_usage_error(cli):
    r = cli("no-such-command")
    assert r.exit_code == 2


@pytest.mark.parametrize("env, expected", [
    ({"NUMBA_CACHE_DIR": "/tmp/given"}, "/tmp/given"),
    ({"XDG_CACHE_HOME": "/tmp/xdg"}, "/tmp/xdg/sarcli/numba"),
    ({"XDG_CACHE_HOME": "relative/ignored", "HOME": "/tmp/home"}, "/tmp/home/.cache/sarcli/numba"),
    ({"HOME": "/tmp/home"}, "/tmp/home/.cache/sarcli/numba"),
])
def test_numba_cache_folder(env, expected):
    """Set for numba when sarcli is imported (XDG base directory spec: a relative XDG_CACHE_HOME is ignored)."""
    base = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME", "HOME")}
    code = "import sarcli, numba.core.config as c; print(c.CACHE_DIR)"
    r = subprocess.run([sys.executable, "-c", code], env={**base, **env}, capture_output=True, text=True,
                       check=True)
    assert Path(r.stdout.strip()) == Path(expected)
