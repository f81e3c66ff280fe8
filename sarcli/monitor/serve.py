"""Serve a campaign's live page over HTTP on the loopback interface only (127.0.0.1), for a browser on
the site laptop: ``index.html`` (also at ``/``), ``alarms.csv`` and ``monitor.log``, nothing else,
never cached (the page reloads itself). The page works as a file too; this only saves the browser
from file:// restrictions some kiosks have.
"""

from __future__ import annotations

import http.server
import os
from pathlib import Path

SERVED = {"/": ("index.html", "text/html; charset=utf-8"), "/index.html": ("index.html", "text/html; charset=utf-8"),
          "/alarms.csv": ("alarms.csv", "text/csv; charset=utf-8"),
          "/monitor.log": ("monitor.log", "text/plain; charset=utf-8")}
HOST = "127.0.0.1"


def make_server(root: str | os.PathLike, port: int) -> http.server.ThreadingHTTPServer:
    """A server bound to 127.0.0.1:``port`` (0: any free port) for the campaign folder ``root``."""
    folder = Path(root).resolve()

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self) -> None:  # noqa: N802 (the standard library's name)
            name = self.path.split("?", 1)[0]
            if name not in SERVED:
                self.send_error(404, "only index.html, alarms.csv and monitor.log are served")
                return
            file, ctype = SERVED[name]
            try:
                body = (folder / file).read_bytes()
            except FileNotFoundError:
                self.send_error(404, f"{file} is not written yet")
                return
            self.send_response(200)
            self.send_header("Content-Type", ctype)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, format: str, *args) -> None:  # noqa: A002 (the standard library's signature)
            pass

    return http.server.ThreadingHTTPServer((HOST, port), Handler)
