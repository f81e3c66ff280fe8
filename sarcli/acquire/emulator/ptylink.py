"""Pseudo-terminal plumbing for emulated instruments: one ``os.openpty`` pair per device.

The client opens ``os.ttyname(slave)`` like a real serial port. The emulator keeps its own slave
descriptor open (otherwise reads on the master fail whenever the client closes) and talks on the
master, non-blocking, from one service thread. "Unplugging" closes the master: client reads then
fail the way pyserial reports a vanished USB device.
"""

from __future__ import annotations

import os
import select
import threading
import time
import tty


class PtyDevice:
    """Base class: subclasses implement :meth:`feed` (bytes from the host) and :meth:`tick`."""

    name = "device"

    def __init__(self) -> None:
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        os.set_blocking(self.master, False)
        self.path = os.ttyname(self.slave)
        self.out = bytearray()
        self.unplugged = False
        self.now = time.monotonic()

    def feed(self, data: bytes) -> None:
        raise NotImplementedError

    def tick(self) -> None:
        """Advance internal time-dependent state (sweeps, motion, read windows)."""

    def wakeup_s(self) -> float:
        """How soon :meth:`tick` needs to run again."""
        return 0.1

    def send(self, data: bytes) -> None:
        if not self.unplugged:
            self.out += data

    def unplug(self) -> None:
        """Close the master side now (the client sees the device vanish)."""
        if not self.unplugged:
            self.unplugged = True
            self.out.clear()
            os.close(self.master)

    def close(self) -> None:
        self.unplug()
        os.close(self.slave)


class Service:
    """One thread serving several :class:`PtyDevice` objects until :meth:`stop`."""

    def __init__(self, devices: list[PtyDevice]):
        self.devices = devices
        self._stop = threading.Event()
        self.thread = threading.Thread(target=self._run, name="sarcli-emulator", daemon=True)
        self.error: BaseException | None = None

    def start(self) -> None:
        self.thread.start()

    def _run(self) -> None:
        try:
            while not self._stop.is_set():
                live = [d for d in self.devices if not d.unplugged]
                if not live:
                    time.sleep(0.05)
                    continue
                timeout = max(0.0, min([0.1] + [d.wakeup_s() for d in live]))
                rl = [d.master for d in live]
                wl = [d.master for d in live if d.out]
                r, w, _ = select.select(rl, wl, [], timeout)
                now = time.monotonic()
                for d in live:
                    d.now = now
                    if d.master in w and not d.unplugged:
                        try:
                            n = os.write(d.master, d.out)
                            del d.out[:n]
                        except BlockingIOError:
                            pass
                    if d.master in r and not d.unplugged:
                        try:
                            data = os.read(d.master, 65536)
                        except (BlockingIOError, OSError):
                            data = b""
                        if data:
                            d.feed(data)
                    if not d.unplugged:
                        d.tick()
        except BaseException as e:  # surfaced by stop(); the emulator must not die silently
            self.error = e

    def stop(self) -> None:
        self._stop.set()
        self.thread.join(timeout=5)
        for d in self.devices:
            try:
                d.close()
            except OSError:
                pass
