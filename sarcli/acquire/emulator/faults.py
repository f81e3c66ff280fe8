"""Fault injection plan for the emulator: ``NAME@N[:ARG]`` items, comma separated.

Each fault fires once, at the N-th (1-based) event of its kind since the emulator started:

===================  ==========================  ================================================
name                 counted event               effect
===================  ==========================  ================================================
``vna-timeout``      OUTPDATA answers            the answer is never sent (client times out)
``garble``           OUTPDATA answers            one character of the answer is corrupted
``truncate``         OUTPDATA answers            the answer stops at 60 % (no final LF / short block)
``slow-sweep``       sweeps (SING)               the sweep takes ARG s (default 4 s > 3 s ``++read``)
``vna-unplug``       sweeps (SING)               the VNA port closes (USB unplugged)
``grbl-error``       rail moves (G0/G1 X..)      answered ``error:ARG`` (default 2) and not executed
``alarm``            rail moves                  ``ALARM:ARG`` (default 1, hard limit) half way,
                                                 then ``[MSG:Reset to continue]``; only 0x18 served
``stall``            rail moves                  the axis stops half way, state Idle
``lost-ok``          rail moves                  the move is executed but its ``ok`` never sent
``status-garble``    status reports (``?``)      the report is cut short
``rail-unplug``      rail moves                  the rail port closes mid-move
===================  ==========================  ================================================
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field

from sarcli.errors import SarcliError

FAULTS = {
    "vna-timeout": "data", "garble": "data", "truncate": "data",
    "slow-sweep": "sweep", "vna-unplug": "sweep",
    "grbl-error": "move", "alarm": "move", "stall": "move", "rail-unplug": "move", "lost-ok": "move",
    "status-garble": "status",
}
DEFAULT_ARG = {"slow-sweep": 4.0, "grbl-error": 2.0, "alarm": 1.0}


@dataclass
class FaultPlan:
    """Which fault fires at which event count; :meth:`event` advances a counter and reports faults."""

    items: dict[str, dict[int, list[tuple[str, float]]]] = field(default_factory=lambda: defaultdict(dict))
    counts: dict[str, int] = field(default_factory=lambda: defaultdict(int))
    fired: list[str] = field(default_factory=list)

    @classmethod
    def parse(cls, spec: str | None) -> FaultPlan:
        plan = cls()
        for item in (spec or "").split(","):
            item = item.strip()
            if not item:
                continue
            name, _, rest = item.partition("@")
            n_text, _, arg_text = rest.partition(":")
            if name not in FAULTS:
                raise SarcliError(f"unknown fault '{name}' (known: {', '.join(FAULTS)})")
            try:
                n = int(n_text)
                arg = float(arg_text) if arg_text else DEFAULT_ARG.get(name, 0.0)
            except ValueError:
                raise SarcliError(f"fault '{item}' must look like NAME@N or NAME@N:ARG") from None
            if n < 1:
                raise SarcliError(f"fault '{item}': N counts events from 1")
            plan.items[FAULTS[name]].setdefault(n, []).append((name, arg))
        return plan

    def event(self, kind: str) -> dict[str, float]:
        """Count one event of ``kind``; return the faults (name -> arg) that fire now."""
        self.counts[kind] += 1
        due = self.items.get(kind, {}).get(self.counts[kind], [])
        self.fired.extend(f"{name}@{self.counts[kind]}" for name, _ in due)
        return dict(due)
