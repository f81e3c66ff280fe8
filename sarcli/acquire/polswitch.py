"""Polarization switching: which antenna transmits (TX) and which receives (RX).

A full-polarimetric GB-SAR with a 2-port VNA puts one SPDT switch on port 1 (TX V/H) and one on
port 2 (RX V/H). Names are TX letter then RX letter ("VH": transmit V, receive H).

Implementations (all behind :class:`PolSwitch`):

- :class:`SinglePolarization` (default): no switch, one fixed polarization;
- :class:`GrblPinSwitch`: the rail controller's outputs, TX on coolant flood (``M8`` = H,
  ``M9`` = V, Uno pin A3), RX on spindle enable (``M3 S<s>`` = H, ``M5`` = V, pin D11). GRBL executes
  them after queued motion and answers ``ok``; a ``G4`` dwell gives the relays time to settle;
- :class:`Switch11713A`: an HP/Agilent 11713A attenuator/switch driver on the same GPIB bus,
  listen-only, ``A<digits>`` energizes and ``B<digits>`` releases drivers; S9 drives TX, S0 drives RX.
"""

from __future__ import annotations

import time
from typing import Protocol

from sarcli.acquire.errors import InstrumentError
from sarcli.acquire.grbl import GrblRail
from sarcli.acquire.prologix import Prologix

SWITCH_KINDS = ("none", "grbl", "11713a")


class PolSwitch(Protocol):
    kind: str

    def select(self, pol: str) -> None:
        """Route TX and RX for polarization ``pol`` and return once the switches have settled."""


def _tx_rx(pol: str) -> tuple[bool, bool]:
    """(TX is H, RX is H) for a polarization name."""
    if len(pol) != 2 or any(c not in "VH" for c in pol):
        raise InstrumentError(f"unknown polarization '{pol}' (expected VV, VH, HV or HH)")
    return pol[0] == "H", pol[1] == "H"


class SinglePolarization:
    """No switch: the antennas are wired for one polarization."""

    kind = "none"

    def __init__(self, pol: str):
        _tx_rx(pol)
        self.pol = pol

    def select(self, pol: str) -> None:
        if pol != self.pol:
            raise InstrumentError(f"no polarization switch configured: cannot measure {pol} (wired {self.pol})")


class GrblPinSwitch:
    """TX on ``M8``/``M9``, RX on ``M3 S..``/``M5`` of the rail's GRBL; ``settle_s`` dwell after."""

    kind = "grbl"

    def __init__(self, rail: GrblRail, spindle_s: int = 1000, settle_s: float = 0.05):
        self.rail, self.spindle_s, self.settle_s = rail, int(spindle_s), float(settle_s)
        self.state: tuple[bool, bool] | None = None

    def select(self, pol: str) -> None:
        tx_h, rx_h = _tx_rx(pol)
        if self.state == (tx_h, rx_h):
            return
        self.rail.command("M8" if tx_h else "M9")
        self.rail.command(f"M3 S{self.spindle_s}" if rx_h else "M5")
        if self.settle_s > 0:
            self.rail.command(f"G4 P{self.settle_s:g}", timeout_s=self.settle_s + self.rail.timeout_s)
        self.state = (tx_h, rx_h)


class Switch11713A:
    """An 11713A at GPIB ``address`` (factory 28: uncertain, to verify on hardware) on the VNA's Prologix;
    S9 = TX, S0 = RX."""

    kind = "11713a"

    def __init__(self, gpib: Prologix, address: int = 28, settle_s: float = 0.07):
        self.gpib, self.address, self.settle_s = gpib, int(address), float(settle_s)
        self.state: tuple[bool, bool] | None = None

    @staticmethod
    def command_for(pol: str) -> str:
        tx_h, rx_h = _tx_rx(pol)
        on = ("9" if tx_h else "") + ("0" if rx_h else "")
        off = ("" if tx_h else "9") + ("" if rx_h else "0")
        return (f"A{on}" if on else "") + (f"B{off}" if off else "")

    def select(self, pol: str) -> None:
        tx_rx = _tx_rx(pol)
        if self.state == tx_rx:
            return
        self.gpib.select(self.address)
        self.gpib.write(self.command_for(pol))
        if self.settle_s > 0:  # listen-only: no readback, wait the switch + driver time
            time.sleep(self.settle_s)
        self.state = tx_rx
