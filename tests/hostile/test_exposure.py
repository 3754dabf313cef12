"""Hostile tests of issue 45 (the second hardening campaign), HTTP and spec
side: multi-range answers built in memory (item 1), any web page using the
default set-up through Host, Origin and simple bodies (item 3), stages
validated in quadratic time (item 4), brotli's unbounded cost (item 6),
loose header parsing (item 9), If-Range and names (item 10). Each starts
its own hmpm-server on loopback.
"""

from __future__ import annotations

import copy
import json
import os
import re
import socket
import threading
import time
import unittest

from tests.hostile.support import BAR_SPEC, ServerProcess, record
from tests.hostile.test_http import (connect, host_port, raw, request, rss_kib, status_of,
                                     submit_and_finish)

ISSUE = 45


def host_header(server: ServerProcess) -> str:
    host, port = host_port(server)
    return f"{host}:{port}"


class MultiRangeTest(unittest.TestCase):
    """Item 1: `Range: bytes=0-,0-,...` (2 600 ranges in an 8 KB request)
    made a 31.9 MB multipart answer of /ui/style.css, built in memory, for
    anyone (no token needed); clients that do not read kept it there."""

    CLIENTS = 12

    def test_many_ranges_get_the_whole_answer_once(self):
        with ServerProcess(workers=1, token="t-item1") as server:
            status, _, css = request(server, "GET", "/ui/style.css")
            self.assertEqual(status, 200)
            ranges = "bytes=" + ",".join(["0-"] * 2600)
            status, headers, body = request(server, "GET", "/ui/style.css",
                                            headers={"Range": ranges}, timeout=30)
            # Before: 206 multipart/byteranges of 2 600 copies (31.9 MB).
            self.assertEqual(status, 200, headers)
            self.assertEqual(body, css)
            # Two ranges: the whole file too (RFC 9110 lets a server ignore Range).
            status, _, body = request(server, "GET", "/ui/style.css",
                                      headers={"Range": "bytes=0-9,20-29"})
            self.assertEqual((status, body), (200, css))
            # One range still works.
            status, _, body = request(server, "GET", "/ui/style.css", headers={"Range": "bytes=0-9"})
            self.assertEqual((status, body), (206, css[:10]))

            # Clients that send the many-range request and never read.
            pid = server.proc.pid
            before = rss_kib(pid)
            head = (f"GET /ui/style.css HTTP/1.1\r\nHost: {host_header(server)}\r\n"
                    f"Range: {ranges}\r\nAccept-Encoding: br\r\n\r\n").encode()
            socks = []
            for _ in range(self.CLIENTS):
                s = connect(server, 10.0)
                s.sendall(head * 4)  # four pipelined requests each
                socks.append(s)
            time.sleep(3.0)
            peak = rss_kib(pid)
            for s in socks:
                s.close()
            grown = (peak - before) / 1024
            # Before: about 32 MB per request held for the unread answer.
            self.assertLess(grown, 100, f"RSS {before} -> {peak} KiB")
            self.assertEqual(request(server, "GET", "/health")[0], 200)
        record(issue=ISSUE, item=1, bad_inputs=3 + 4 * self.CLIENTS,
               rss_growth_mib=round(grown, 1), load=f"{self.CLIENTS} unread clients x 4 requests")


class ExposureTest(unittest.TestCase):
    """Item 3: the default set-up (loopback, no token) answered any Host,
    and took `text/plain` and form bodies from any Origin (201)."""

    def test_host_origin_and_content_type(self):
        bad = 0
        spec = json.dumps(BAR_SPEC).encode()
        with ServerProcess(workers=1) as server:
            host, port = host_port(server)
            own = f"{host}:{port}"
            # Host: a DNS-rebinding page sends its own name.
            for value in ("evil.example", f"evil.example:{port}", f"{host}:1", "[::1", ""):
                status, _, _ = request(server, "GET", "/jobs", headers={"Host": value})
                self.assertEqual(status, 421 if value else 400, value)
                bad += 1
            for value in (own, f"localhost:{port}", host):
                status, _, _ = request(server, "GET", "/jobs", headers={"Host": value})
                self.assertEqual(status, 200, value)

            # Bodies a form or a "simple" cross-site request can send.
            for ctype in ("text/plain", "application/x-www-form-urlencoded",
                          "multipart/form-data; boundary=x", None):
                headers = {"Content-Type": ctype} if ctype else {}
                status, _, body = request(server, "POST", "/jobs", spec, headers)
                self.assertEqual(status, 415, (ctype, body[:200]))
                bad += 1
            status, _, _ = request(server, "POST", "/jobs", spec,
                                   {"Content-Type": "application/json; charset=utf-8"})
            self.assertEqual(status, 201)

            # Origin: writes from another page are refused, the dashboard's
            # own origin works; no CORS header for strangers.
            json_type = {"Content-Type": "application/json"}
            for origin in ("http://evil.example", "null", f"http://{host}:1"):
                status, h, _ = request(server, "POST", "/jobs", spec, {**json_type, "Origin": origin})
                self.assertEqual(status, 403, origin)
                self.assertNotIn("access-control-allow-origin", h)
                bad += 1
            status, _, body = request(server, "POST", "/jobs", spec,
                                      {**json_type, "Origin": f"http://{own}"})
            self.assertEqual(status, 201, body[:200])
            job = json.loads(body)["jobID"]
            for method, path in (("DELETE", f"/jobs/{job}"), ("POST", f"/jobs/{job}/cancel")):
                status, _, _ = request(server, method, path,
                                       headers={"Origin": "http://evil.example"})
                self.assertEqual(status, 403, path)
                bad += 1
            status, h, _ = request(server, "GET", "/jobs", headers={"Origin": "http://evil.example"})
            self.assertEqual(status, 200)
            self.assertNotIn("access-control-allow-origin", h)
            # A body-less POST (what `curl -d ''` and the dashboard send to cancel).
            status, _, _ = request(server, "POST", f"/jobs/{job}/cancel", b"",
                                   {"Content-Type": "application/x-www-form-urlencoded"})
            self.assertIn(status, (200, 202, 409))

        # Configured names and origins.
        with ServerProcess(workers=1, extra=["--allowed-host", "hmpm.example",
                                             "--allowed-origin", "https://app.example"]) as server:
            self.assertEqual(request(server, "GET", "/jobs", headers={"Host": "hmpm.example"})[0], 200)
            self.assertEqual(request(server, "GET", "/jobs", headers={"Host": "other.example"})[0],
                             421)
            status, h, _ = request(server, "POST", "/jobs", spec,
                                   {"Content-Type": "application/json", "Origin": "https://app.example"})
            self.assertEqual(status, 201)
            self.assertEqual(h.get("access-control-allow-origin"), "https://app.example")
            status, h, _ = request(server, "OPTIONS", "/jobs",
                                   headers={"Origin": "https://app.example",
                                            "Access-Control-Request-Method": "POST"})
            self.assertEqual(status, 204)
            self.assertIn("Content-Type", h.get("access-control-allow-headers", ""))
            bad += 1
        record(issue=ISSUE, item=3, bad_inputs=bad)


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of process `pid` so far."""
    fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


class BrotliTest(unittest.TestCase):
    """Item 6: brotli (httplib's, quality 11) cost 30 times gzip's CPU with no
    bound (/jobs?limit=1000: 1.76 s against 0.06 s). The large answer here
    is a 1 000-stage spec (GET /jobs/{id}/spec, about 250 kB)."""

    def test_brotli_cost_is_bounded(self):
        spec = staged_spec(1000)
        for i, stage in enumerate(spec["stages"]):
            stage["name"] = f"lift {i:04d} of the embankment, " + "fill placed and compacted " * 6
        body = json.dumps(spec).encode()
        with ServerProcess(workers=1) as server:
            job = submit_and_finish(server, spec)
            path = f"/jobs/{job}/spec"
            pid = server.proc.pid
            costs = {}
            for encoding in ("identity", "gzip", "br", "gzip, deflate, br"):
                start = cpu_seconds(pid)
                for _ in range(3):
                    status, headers, answer = request(server, "GET", path,
                                                      headers={"Accept-Encoding": encoding}, timeout=30)
                    self.assertEqual(status, 200)
                costs[encoding] = (cpu_seconds(pid) - start) / 3
                if encoding == "identity":
                    self.assertEqual(answer, body)
                else:
                    # Too large for brotli: gzip when the client takes it, else as it is.
                    self.assertEqual(headers.get("content-encoding"),
                                     None if encoding == "br" else "gzip", (encoding, costs))
            # Small answers keep brotli.
            _, headers, _ = request(server, "GET", "/ui/app.js", headers={"Accept-Encoding": "br"})
            self.assertEqual(headers.get("content-encoding"), "br")
            # Before: about 0.5 s of CPU per request for "br" (httplib's quality 11).
            self.assertLess(costs["br"], 0.1, costs)
        record(issue=ISSUE, item=6, bad_inputs=6, answer_kb=len(body) // 1000,
               cpu_ms_per_request={k: round(v * 1000) for k, v in costs.items()})


class SlowReaderTest(unittest.TestCase):
    """Item 5: downloads failed below about 2 MB/s (a 78 MB file at 100-1000
    kB/s was cut after 6-20 MB). The campaign's client, curl --limit-rate,
    reads in bursts and pauses between them (at 200 kB/s: 10 MB at once,
    then about 50 s), and the server gave up once its send buffer had not
    drained for 5 s. (A reader taking the same average in small steady reads
    is served by the old server too: its send queue shrinks all along.)

    Here a 7.8 MB snapshot (more than the socket buffers hold) is read like
    that at 200 kB/s: 1.4 MB at once, a 7 s pause, twice, then the rest at
    full speed. Beside it a client that reads nothing, which must be
    dropped at the stall timeout (--send-stall-timeout 12 here, 120 s by
    default; docs/api.md "Operations"), freeing its thread.
    The full campaign case (78 MB, curl --limit-rate 200k, 6.5 min) is a
    manual command: docs/api.md, "Operations"."""

    RATE = 200_000  # bytes per second on average over the bursts and pauses
    BURST = 1_400_000
    PAUSES = 2
    STALL_S = 12.0

    def test_slow_reader_served_stalled_one_dropped(self):
        spec = copy.deepcopy(BAR_SPEC)
        spec["grid"]["cells"] = [20000]
        spec["time"] = {"end": 2e-6, "dt": 1e-6}
        spec["output"]["series"]["interval"] = 1e-6
        spec["output"]["snapshots"] = {"interval": 1e-3}
        with ServerProcess(workers=1, extra=["--send-stall-timeout", str(self.STALL_S)]) as server:
            job = submit_and_finish(server, spec)
            _, _, manifest = request(server, "GET", f"/jobs/{job}/results")
            file = next(f for f in json.loads(manifest)["files"] if f["name"].endswith(".vtu"))
            head = (f"GET /jobs/{job}/results/{file['name']} HTTP/1.1\r\n"
                    f"Host: {host_header(server)}\r\n\r\n").encode()

            stalled = {"got": 0, "closed_after_s": None}

            def stalled_reader():
                with connect(server, 60.0) as s:
                    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 65536)
                    t0 = time.monotonic()
                    s.sendall(head)
                    time.sleep(self.STALL_S + 4)  # reads nothing past the stall timeout
                    try:
                        while True:
                            b = s.recv(1 << 20)
                            if not b:
                                break
                            stalled["got"] += len(b)
                    except OSError:
                        pass
                    stalled["closed_after_s"] = time.monotonic() - t0

            t = threading.Thread(target=stalled_reader, daemon=True)
            t.start()
            start = time.monotonic()
            pauses = []
            with connect(server, 60.0) as s:
                s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 65536)
                s.sendall(head)
                data = b""
                while b"\r\n\r\n" not in data:
                    data += s.recv(4096)
                self.assertEqual(status_of(data), 200, data[:300])
                got = len(data.split(b"\r\n\r\n", 1)[1])
                try:
                    while got < file["size"]:
                        b = s.recv(65536)
                        if not b:
                            break
                        got += len(b)
                        if len(pauses) < self.PAUSES and got >= self.BURST * (len(pauses) + 1):
                            # The burst's worth at RATE, less the time the burst took.
                            pause = self.BURST * (len(pauses) + 1) / self.RATE - (time.monotonic() - start)
                            pauses.append(round(pause, 1))
                            time.sleep(max(pause, 0.0))
                except OSError:
                    pass
            took = time.monotonic() - start
            t.join(60)
            # Before: cut at the first pause (the send queue did not drain for 5 s).
            self.assertEqual(got, file["size"], f"cut after {got} of {file['size']} bytes, "
                                                f"{took:.1f} s, pauses {pauses}")
            self.assertTrue(all(p > 5.5 for p in pauses), f"pauses too short to tell: {pauses}")
            self.assertLess(stalled["got"], file["size"], "the stalled reader was not dropped")
            self.assertEqual(request(server, "GET", "/health")[0], 200)
        record(issue=ISSUE, item=5, bad_inputs=1,
               download=f"{file['size'] / 1e6:.1f} MB in bursts of {self.BURST / 1e6:.1f} MB with "
               f"pauses of {pauses} s ({self.RATE / 1000:.0f} kB/s), in {took:.1f} s",
               stalled_reader=f"dropped after {self.STALL_S:.0f} s stall timeout, "
               f"got {stalled['got']} bytes")


class StrictHeadTest(unittest.TestCase):
    """Item 9: heads a front proxy could read differently from the server."""

    def test_malformed_heads_are_400(self):
        bad = 0
        with ServerProcess(workers=1) as server:
            h = host_header(server).encode()
            body = json.dumps(BAR_SPEC).encode()
            n = len(body)
            cases = {
                # Two different Content-Length: the first won, the rest of the
                # body ran as a second request.
                "two Content-Length": b"POST /jobs HTTP/1.1\r\nHost: " + h +
                b"\r\nContent-Type: application/json\r\nContent-Length: %d\r\nContent-Length: 5\r\n\r\n"
                % n + body,
                "Content-Length list": b"POST /jobs HTTP/1.1\r\nHost: " + h +
                b"\r\nContent-Type: application/json\r\nContent-Length: %d, 5\r\n\r\n" % n + body,
                "space before colon": b"POST /jobs HTTP/1.1\r\nHost: " + h +
                b"\r\nContent-Type: application/json\r\nTransfer-Encoding : chunked\r\n"
                b"Content-Length: %d\r\n\r\n" % n + body,
                "obs-fold": b"GET /health HTTP/1.1\r\nHost: " + h + b"\r\nX-A: 1\r\n  folded\r\n\r\n",
                "no colon": b"GET /health HTTP/1.1\r\nHost: " + h + b"\r\nNoColonHere\r\n\r\n",
                "NUL": b"GET /health HTTP/1.1\r\nHost: " + h + b"\r\nX-A: a\x00b\r\n\r\n",
                "bare LF": b"GET /health HTTP/1.1\r\nHost: " + h + b"\nX-A: 1\r\n\r\n",
                "control character": b"GET /health HTTP/1.1\r\nHost: " + h + b"\r\nX-A: a\x01b\r\n\r\n",
                "no Host": b"GET /health HTTP/1.1\r\n\r\n",
                "two Hosts": b"GET /health HTTP/1.1\r\nHost: " + h + b"\r\nHost: " + h + b"\r\n\r\n",
            }
            for name, data in cases.items():
                answer = raw(server, data)
                self.assertEqual(status_of(answer), 400, (name, answer[:300]))
                # Nothing after it: one answer, the connection closed.
                self.assertEqual(len(re.findall(rb"HTTP/1\.1 \d{3} ", answer)), 1, (name, answer[:600]))
                bad += 1
            # What stays accepted: HTTP/1.0 without Host; the same length twice.
            self.assertEqual(status_of(raw(server, b"GET /health HTTP/1.0\r\n\r\n")), 200)
            same = raw(server, b"POST /validate HTTP/1.1\r\nHost: " + h +
                              b"\r\nContent-Type: application/json\r\nContent-Length: %d\r\n"
                              b"Content-Length: %d\r\nConnection: close\r\n\r\n" % (n, n) + body)
            self.assertEqual(status_of(same), 200, same[:300])
            # No job came from a smuggled second request.
            status, _, listing = request(server, "GET", "/jobs")
            self.assertEqual(json.loads(listing)["jobs"], [], listing[:300])
        record(issue=ISSUE, item=9, bad_inputs=bad)


class IfRangeAndNamesTest(unittest.TestCase):
    """Item 10: If-Range was ignored (a stale tag still got 206); names were
    limited in bytes, not characters, and took invisible characters."""

    def test_if_range(self):
        with ServerProcess(workers=1) as server:
            job = submit_and_finish(server, BAR_SPEC)
            path = f"/jobs/{job}/results/summary.json"
            status, headers, whole = request(server, "GET", path)
            self.assertEqual(status, 200)
            etag = headers["etag"]
            status, _, part = request(server, "GET", path, headers={"Range": "bytes=0-9", "If-Range": etag})
            self.assertEqual((status, part), (206, whole[:10]))
            for stale in ('"stale"', "W/" + etag, "Sat, 05 Dec 2026 08:00:00 GMT"):
                status, _, body = request(server, "GET", path,
                                          headers={"Range": "bytes=0-9", "If-Range": stale})
                self.assertEqual((status, body), (200, whole), stale)
            # Routes without validators: If-Range cannot match, the whole answer.
            status, _, _ = request(server, "GET", "/ui/style.css",
                                   headers={"Range": "bytes=0-9", "If-Range": '"x"'})
            self.assertEqual(status, 200)
        record(issue=ISSUE, item=10, bad_inputs=4)


def staged_spec(stages: int, boundaries_per_stage: int = 0) -> dict:
    """BAR_SPEC cut to one step, then `stages` stages of one step each."""
    spec = copy.deepcopy(BAR_SPEC)
    spec["time"] = {"end": 0.001, "dt": 1e-3}
    spec["output"]["series"]["interval"] = 0.001
    spec["output"]["snapshots"] = {"interval": 1.0}
    bc = {"nodes": {"box": {"min": [0.0], "max": [0.0]}}, "velocity": [0.0]}
    spec["stages"] = [dict({"end": 0.001 * (i + 2), "gravity": [0.0]},
                           **({"boundaries": [bc] * boundaries_per_stage} if boundaries_per_stage else {}))
                      for i in range(stages)]
    return spec


class StagesTest(unittest.TestCase):
    """Item 4: validating `stages` took time quadratic in their number (1 000
    stages 2.2 s, 5 000 325 s while other submits got 503); the 16 MB body
    limit allowed about 25 000."""

    def test_many_stages_are_refused_or_validated_quickly(self):
        bad = 0
        figures = {}
        with ServerProcess(workers=1) as server:
            cases = {
                # The body limit's worth: 16 MB of stages.
                "16 MB of stages": (staged_spec(1), 400),
                # The campaign's 1 000 stages: validated, now in well under 2 s.
                "1000 stages": (staged_spec(1000), 200),
                # Fewer stages, each with many boundaries: the product is bounded.
                "100 stages x 300 boundaries": (staged_spec(100, 300), 400),
            }
            one = json.dumps(cases["16 MB of stages"][0]["stages"][0])
            big = cases["16 MB of stages"][0]
            count = (16_000_000 - 2000) // (len(one) + 2)
            while True:
                big["stages"] = [dict(big["stages"][0], end=0.001 * (i + 2)) for i in range(count)]
                size = len(json.dumps(big))
                if size <= 16 << 20:
                    break
                count = int(count * (16 << 20) / size) - 100
            for name, (spec, want) in cases.items():
                body = json.dumps(spec).encode()
                self.assertLessEqual(len(body), 16 << 20, name)
                start = time.monotonic()
                status, _, answer = request(server, "POST", "/validate", body,
                                            {"Content-Type": "application/json"}, timeout=30)
                took = time.monotonic() - start
                self.assertEqual(status, want, (name, answer[:300]))
                if want == 400:
                    self.assertEqual(json.loads(answer)["errors"][0]["path"], "/stages", answer[:300])
                    bad += 1
                self.assertLess(took, 2.0, name)
                figures[name] = f"{len(body) / 1e6:.1f} MB {took:.2f} s"
            self.assertEqual(request(server, "GET", "/health")[0], 200)
        record(issue=ISSUE, item=4, bad_inputs=bad, **{k.replace(" ", "_"): v for k, v in figures.items()})


class NamesTest(unittest.TestCase):
    """Item 10: names limited in bytes, not characters; invisible ones taken."""

    def test_names_in_characters_without_invisible_ones(self):
        bad = 0
        with ServerProcess(workers=1) as server:
            def validate(spec):
                status, _, body = request(server, "POST", "/validate", json.dumps(spec).encode(),
                                          {"Content-Type": "application/json"})
                return status, json.loads(body)

            spec = copy.deepcopy(BAR_SPEC)
            spec["name"] = "\u00e9" * 200  # 200 characters, 400 bytes
            self.assertEqual(validate(spec)[0], 200)
            spec["name"] = "\u00e9" * 201
            status, doc = validate(spec)
            self.assertEqual((status, doc["errors"][0]["path"]), (400, "/name"))
            self.assertIn("201 characters", doc["errors"][0]["message"])
            bad += 1
            for invisible in ("\u200b", "\u200d", "\ufeff", "\u00ad", "\u2060", "\U000e0041"):
                spec["name"] = f"bar{invisible}test"
                status, doc = validate(spec)
                self.assertEqual((status, doc["errors"][0]["path"]), (400, "/name"), invisible)
                bad += 1
            staged = staged_spec(1)
            staged["stages"][0]["name"] = "lift\u200b1"
            status, doc = validate(staged)
            self.assertEqual((status, doc["errors"][0]["path"]), (400, "/stages/0/name"))
            bad += 1
        record(issue=ISSUE, item=10, bad_inputs=bad)


if __name__ == "__main__":
    unittest.main()
