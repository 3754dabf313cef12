#!/usr/bin/env python3
"""Development proxy for the dashboard, until hmpm-server serves it itself.

Serves server/ui/ at /ui (index.html at /ui and /ui/), examples/ at
/ui/examples/ (with a generated /ui/examples/index.json), answers
POST /validate by running `hmpm validate -`, and forwards every other request
to a real hmpm-server (responses are streamed, so /jobs/{id}/events works).

    python3 tests/browser/dev_proxy.py --upstream http://127.0.0.1:PORT \
        [--port 0] [--hmpm /tmp/base-bin/hmpm]

The first line on stdout is `listening on http://127.0.0.1:PORT`, as for
hmpm-server. Standard library only; loopback only.
"""

import argparse
import http.client
import http.server
import json
import mimetypes
import re
import subprocess
import sys
import urllib.parse
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
HOP_HEADERS = {"connection", "keep-alive", "transfer-encoding", "te", "trailer", "upgrade",
               "proxy-authorization", "proxy-authenticate"}
TYPES = {".js": "text/javascript; charset=utf-8", ".css": "text/css; charset=utf-8",
         ".html": "text/html; charset=utf-8", ".json": "application/json", ".svg": "image/svg+xml"}
COST_LINE = re.compile(r"([a-z][a-z -]*?) ~?([0-9.e+-]+)(?: (KiB|MiB|GiB))?(?: \(dt ([0-9.e+-]+) s\))?")
UNITS = {"KiB": 1024, "MiB": 1024 ** 2, "GiB": 1024 ** 3}


def parse_cost(text):
    """The cost line `hmpm validate` prints ("particles 40, nodes 41, steps
    1417175 (dt 3.6e-05 s), ...") as a dict like the server's `cost`."""
    cost = {}
    for line in text.splitlines():
        if not line.startswith("particles "):
            continue
        for part in line.split(", "):
            m = COST_LINE.fullmatch(part.strip())
            if not m:
                continue
            key = m.group(1).replace(" ", "_").replace("-", "_")
            value = float(m.group(2))
            if m.group(3):
                key, value = f"{key}_bytes", value * UNITS[m.group(3)]
            cost[key] = int(value) if value.is_integer() else value
            if m.group(4):
                cost["dt"] = float(m.group(4))
    return cost


def validate(hmpm, body):
    """(status, document) for POST /validate, from `hmpm validate -`."""
    run = subprocess.run([hmpm, "validate", "-"], input=body, capture_output=True, timeout=30)
    out = run.stdout.decode("utf-8", "replace")
    err = run.stderr.decode("utf-8", "replace")
    if run.returncode == 0:
        warnings = []
        for line in err.splitlines():  # "hmpm: warning: /path: message"
            if line.startswith("hmpm: warning: "):
                path, _, message = line[len("hmpm: warning: "):].partition(": ")
                warnings.append({"path": path, "message": message})
        return 200, {"valid": True, "warnings": warnings, "cost": parse_cost(out)}
    if run.returncode == 2:
        errors = []
        for line in err.splitlines():
            path, sep, message = line.partition(": ")
            if sep and (path == "" or path.startswith("/")):
                errors.append({"path": path, "message": message})
            elif line.strip():
                errors.append({"path": "", "message": line.strip()})
        return 400, {"type": "invalid-spec", "title": "Invalid job spec", "status": 400,
                     "detail": f"{len(errors)} problem(s) in the job spec", "errors": errors}
    return 500, {"type": "internal-error", "title": "Internal error", "status": 500,
                 "detail": f"hmpm validate exited {run.returncode}: {err.strip()}"}


class Handler(http.server.BaseHTTPRequestHandler):
    server_version = "hmpm-dev-proxy"
    upstream = None  # urllib.parse.SplitResult
    hmpm = "hmpm"
    ui_dir = REPO / "server" / "ui"
    examples_dir = REPO / "examples"

    def log_message(self, fmt, *args):  # quiet; errors still reach stderr
        pass

    def send(self, status, body, content_type):
        self.send_response(status)
        self.send_header("Content-Type", content_type)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(body)

    def problem(self, status, detail):
        doc = {"type": "not-found", "title": "Not found", "status": status, "detail": detail}
        self.send(status, json.dumps(doc).encode(), "application/problem+json")

    def body(self):
        length = int(self.headers.get("Content-Length") or 0)
        return self.rfile.read(length) if length else b""

    def static(self, path):
        if path in ("/ui", "/ui/"):
            return self.file(self.ui_dir / "index.html")
        if path == "/ui/examples/index.json":
            names = sorted(p.stem for p in self.examples_dir.glob("*.json"))
            return self.send(200, json.dumps(names).encode(), "application/json")
        if path.startswith("/ui/examples/"):
            return self.file(self.examples_dir / path[len("/ui/examples/"):], self.examples_dir)
        return self.file(self.ui_dir / path[len("/ui/"):], self.ui_dir)

    def file(self, target, root=None):
        target = target.resolve()
        if root is not None and root.resolve() not in target.parents:
            return self.problem(404, "no such file")
        if not target.is_file():
            return self.problem(404, f"no such file: {self.path}")
        kind = TYPES.get(target.suffix) or mimetypes.guess_type(target.name)[0] or "application/octet-stream"
        self.send(200, target.read_bytes(), kind)

    def forward(self):
        body = self.body()
        conn = http.client.HTTPConnection(self.upstream.hostname, self.upstream.port, timeout=60)
        headers = {k: v for k, v in self.headers.items() if k.lower() not in HOP_HEADERS and k.lower() != "host"}
        headers["Host"] = self.upstream.netloc
        if self.command in ("POST", "PUT", "PATCH") or body:
            headers["Content-Length"] = str(len(body))
        try:
            conn.request(self.command, self.path, body=body or None, headers=headers)
            resp = conn.getresponse()
        except OSError as exc:
            return self.send(502, json.dumps({"type": "bad-gateway", "title": "Bad gateway", "status": 502,
                                              "detail": f"upstream: {exc}"}).encode(), "application/problem+json")
        self.send_response(resp.status, resp.reason)
        for k, v in resp.getheaders():
            if k.lower() not in HOP_HEADERS:
                self.send_header(k, v)
        self.send_header("Connection", "close")
        self.end_headers()
        try:
            while True:  # stream: Server-Sent Events arrive piece by piece
                chunk = resp.read1(65536) if hasattr(resp, "read1") else resp.read(65536)
                if not chunk:
                    break
                self.wfile.write(chunk)
                self.wfile.flush()
        except (BrokenPipeError, ConnectionResetError):
            pass
        finally:
            conn.close()
        self.close_connection = True

    def route(self):
        path = urllib.parse.urlsplit(self.path).path
        if self.command in ("GET", "HEAD") and (path == "/ui" or path.startswith("/ui/")):
            return self.static(path)
        if self.command == "POST" and path == "/validate":
            status, doc = validate(self.hmpm, self.body())
            kind = "application/json" if status == 200 else "application/problem+json"
            return self.send(status, json.dumps(doc).encode(), kind)
        return self.forward()

    do_GET = do_HEAD = do_POST = do_DELETE = do_PUT = do_PATCH = route


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--upstream", required=True, help="hmpm-server URL, e.g. http://127.0.0.1:8080")
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=0)
    parser.add_argument("--hmpm", default="/tmp/base-bin/hmpm", help="hmpm CLI used for POST /validate")
    args = parser.parse_args()
    Handler.upstream = urllib.parse.urlsplit(args.upstream)
    Handler.hmpm = args.hmpm
    server = http.server.ThreadingHTTPServer((args.host, args.port), Handler)
    server.daemon_threads = True
    print(f"listening on http://{args.host}:{server.server_address[1]}", flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
