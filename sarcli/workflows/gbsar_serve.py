"""``gbsar_serve``: serve a campaign's live page on http://127.0.0.1:PORT/ until stopped
(:mod:`sarcli.monitor.serve`: loopback only, ``index.html``, ``alarms.csv`` and ``monitor.log``)."""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from sarcli.errors import ConfigError
from sarcli.monitor.serve import HOST, make_server
from sarcli.workflows.base import Progress, Report, using


@dataclass(frozen=True)
class Config:
    """campaign: the campaign folder; port: TCP port on 127.0.0.1 (0: any free one)."""

    campaign: Path
    port: int = 8000

    def __post_init__(self) -> None:
        if not 0 <= self.port <= 65535:
            raise ConfigError(f"--port must be in 0..65535, got {self.port}")


@dataclass
class GbsarServeReport(Report):
    url: str

    def lines(self) -> list[str]:
        return [f"stopped serving {self.url}"]


def run(config: Config, provenance=None, progress: Progress | None = None,
        on_ready: Callable[[GbsarServeReport], None] | None = None,
        stop: threading.Event | None = None) -> GbsarServeReport:
    """Serve until ``stop`` is set (default: until SIGINT or SIGTERM); ``on_ready`` gets the URL."""
    with using(provenance):
        if not (config.campaign / "index.html").exists() and not (config.campaign / "campaign.json").exists():
            raise ConfigError(f"{config.campaign} is not a monitoring campaign (no index.html, no campaign.json)")
        try:
            server = make_server(config.campaign, config.port)
        except OSError as e:
            raise ConfigError(f"cannot listen on {HOST}:{config.port} ({e.strerror})") from None
        report = GbsarServeReport(url=f"http://{HOST}:{server.server_address[1]}/")
        done = stop or threading.Event()
        old = {}
        if stop is None and threading.current_thread() is threading.main_thread():
            old = {s: signal.signal(s, lambda *_: done.set()) for s in (signal.SIGINT, signal.SIGTERM)}
        thread = threading.Thread(target=server.serve_forever, kwargs={"poll_interval": 0.2}, daemon=True)
        thread.start()
        try:
            if on_ready is not None:
                on_ready(report)
            while not done.wait(0.2):
                pass
        finally:
            server.shutdown()
            server.server_close()
            for s, handler in old.items():
                signal.signal(s, handler)
        return report
