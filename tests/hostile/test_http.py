"""Hostile tests of the connection level and the HTTP details (hardening
items 2, 4, 9 and 10): slowloris, header floods, unauthenticated bodies,
ranges, conditional requests, half-closed clients, idle event streams,
methods, and insecure starts. Each starts its own hmpm-server on loopback.
"""

from __future__ import annotations

import http.client
import json
import os
import socket
import subprocess
import tempfile
import threading
import time
import unittest
from pathlib import Path

from tests.hostile.support import BAR_SPEC, ServerProcess, record, server_binary
from tests.python.support import long_spec, wait_until

TOKEN = "hostile-http-secret"


def host_port(server: ServerProcess):
    host, port = server.url.split("//", 1)[1].rsplit(":", 1)
    return host, int(port)


def connect(server: ServerProcess, timeout: float = 5.0) -> socket.socket:
    return socket.create_connection(host_port(server), timeout=timeout)


def request(server: ServerProcess, method: str, path: str, body: bytes = b"", headers=None,
            timeout: float = 5.0):
    """One request on a fresh connection: (status, headers, body)."""
    conn = http.client.HTTPConnection(*host_port(server), timeout=timeout)
    try:
        conn.request(method, path, body=body, headers=headers or {})
        res = conn.getresponse()
        return res.status, {k.lower(): v for k, v in res.getheaders()}, res.read()
    finally:
        conn.close()


def raw(server: ServerProcess, data: bytes, timeout: float = 5.0, half_close: bool = False) -> bytes:
    """Sends `data` as it is and reads until the server closes or times out."""
    with connect(server, timeout) as s:
        s.sendall(data)
        if half_close:
            s.shutdown(socket.SHUT_WR)
        chunks = []
        try:
            while True:
                b = s.recv(65536)
                if not b:
                    break
                chunks.append(b)
        except (socket.timeout, ConnectionResetError):
            pass
        return b"".join(chunks)


def status_of(answer: bytes) -> int:
    try:
        return int(answer.split(b" ", 2)[1])
    except (IndexError, ValueError):
        return 0


def rss_kib(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise AssertionError("no VmRSS")


def submit_and_finish(server: ServerProcess, spec: dict, headers=None) -> str:
    status, _, body = request(server, "POST", "/jobs", json.dumps(spec).encode(),
                              {"Content-Type": "application/json", **(headers or {})})
    assert status == 201, (status, body)
    job = json.loads(body)["jobID"]

    def done():
        _, _, b = request(server, "GET", f"/jobs/{job}", headers=headers)
        return json.loads(b)["status"] in ("successful", "failed")
    assert wait_until(done, 60), "job did not finish"
    return job


class SlowlorisTest(unittest.TestCase):
    """Item 2: 64 connections, each sending one header byte a second, for 30 s
    (reconnecting when the server drops them); /health probed on fresh
    connections 4 times a second must answer within 1 s in >= 99 % of probes.
    Directly against the embedded server on loopback (its default)."""

    CONNECTIONS = 64
    SECONDS = 30.0

    def test_slowloris_health(self):
        with ServerProcess(workers=1) as server:
            stop = threading.Event()
            dropped = [0]

            def attacker():
                socks = [None] * self.CONNECTIONS
                while not stop.is_set():
                    for i in range(self.CONNECTIONS):
                        try:
                            if socks[i] is None:
                                socks[i] = connect(server, 2.0)
                                socks[i].sendall(b"GET /health HTTP/1.1\r\nHost: 127.0.0.1\r\n")
                            socks[i].sendall(b"X")
                        except OSError:
                            dropped[0] += 1
                            if socks[i] is not None:
                                socks[i].close()
                            socks[i] = None
                    stop.wait(1.0)
                for s in socks:
                    if s is not None:
                        s.close()

            t = threading.Thread(target=attacker, daemon=True)
            t.start()
            time.sleep(1.5)  # every slow connection is open before probing starts
            probes = answered = 0
            worst = 0.0
            end = time.monotonic() + self.SECONDS
            while time.monotonic() < end:
                probes += 1
                start = time.monotonic()
                try:
                    status, _, _ = request(server, "GET", "/health", timeout=1.0)
                    took = time.monotonic() - start
                    worst = max(worst, took)
                    if status == 200 and took <= 1.0:
                        answered += 1
                except OSError:
                    worst = max(worst, time.monotonic() - start)
                time.sleep(0.25)
            stop.set()
            t.join(10)
            # The acceptance figure of the issue: 99 % of the probes within 1 s.
            self.assertGreaterEqual(answered, 0.99 * probes,
                                    f"{answered}/{probes} probes answered within 1 s; {server.log_tail()}")
            # The head deadline (10 s) must have cut the slow connections off:
            # each of the 64 at least twice in 30 s.
            self.assertGreaterEqual(dropped[0], self.CONNECTIONS)
            record(item=2, requests=answered, probes=probes, worst_probe_s=round(worst, 3),
                   load=f"{self.CONNECTIONS} slowloris connections, {self.SECONDS:.0f} s, direct",
                   slow_connections_cut=dropped[0])


class HeaderAndBodyFloodTest(unittest.TestCase):
    """Item 4: header floods and unauthenticated bodies must not grow the
    server's memory; the 401 comes before the body is read."""

    def test_header_flood_and_unauthenticated_bodies(self):
        with ServerProcess(token=TOKEN, workers=1) as server:
            pid = server.proc.pid
            request(server, "GET", "/health")
            before = rss_kib(pid)
            bad = 0
            # 8 requests with (up to) a million headers each, sent in parallel.
            header_block = b"".join(b"X-%d: y\r\n" % i for i in range(1_000_000))

            def flood():
                with connect(server, 10.0) as s:
                    try:
                        s.sendall(b"GET /health HTTP/1.1\r\nHost: 127.0.0.1\r\n" + header_block + b"\r\n")
                    except OSError:
                        pass  # the server hung up once the limit was passed
                    try:
                        return status_of(s.recv(4096))
                    except OSError:
                        return 0

            results = []
            threads = [threading.Thread(target=lambda: results.append(flood())) for _ in range(8)]
            for t in threads:
                t.start()
            for t in threads:
                t.join(30)
            # 431 when the answer got through, else a closed connection; never 200.
            self.assertTrue(all(r in (0, 431) for r in results), results)
            self.assertIn(431, results)
            bad += len(results)

            # The 401 comes before the body: announce 16 MiB, send none.
            big = 16 << 20
            start = time.monotonic()
            with connect(server, 5.0) as s:
                s.sendall(b"POST /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                          b"Content-Length: %d\r\n\r\n" % big)
                answer = s.recv(4096)
            took = time.monotonic() - start
            self.assertEqual(status_of(answer), 401, answer[:200])
            # Without the fix the server waits for the body (10 s read timeout).
            self.assertLess(took, 1.0)
            bad += 1

            # 20 unauthenticated 16 MiB bodies at once.
            body = b"x" * big
            statuses = []

            def post():
                with connect(server, 10.0) as s:
                    try:
                        s.sendall(b"POST /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: %d\r\n\r\n" % big
                                  + body)
                    except OSError:
                        pass
                    try:
                        statuses.append(status_of(s.recv(4096)))
                    except OSError:
                        statuses.append(0)

            threads = [threading.Thread(target=post) for _ in range(20)]
            for t in threads:
                t.start()
            for t in threads:
                t.join(30)
            self.assertIn(401, statuses)
            self.assertTrue(all(s in (0, 401) for s in statuses), statuses)
            bad += len(statuses)
            after = rss_kib(pid)
            grown_mib = (after - before) / 1024
            # Before the fix: +850 MiB (headers) and +580 MiB (bodies). Bounded
            # now by 64 KiB of head and 16 KiB of buffer per connection; 48 MiB
            # leaves room for thread stacks and allocator slack of 28 threads.
            self.assertLess(grown_mib, 48, f"RSS {before} -> {after} KiB")
            status, _, _ = request(server, "GET", "/health")
            self.assertEqual(status, 200)
            record(item=4, bad_inputs=bad, rss_growth_mib=round(grown_mib, 1),
                   unauthorized_401_s=round(took, 3))


class HttpDetailsTest(unittest.TestCase):
    """Item 9: ranges, conditional requests, half-close, idle event
    streams, OPTIONS and unknown methods."""

    def test_http_details(self):
        bad = 0
        with ServerProcess(workers=1, extra=["--max-event-streams", "2",
                                             "--event-stream-max-seconds", "2"]) as server:
            job = submit_and_finish(server, BAR_SPEC)
            _, _, manifest = request(server, "GET", f"/jobs/{job}/results")
            name = "summary.json"
            size = next(f["size"] for f in json.loads(manifest)["files"] if f["name"] == name)
            path = f"/jobs/{job}/results/{name}"
            status, headers, whole = request(server, "GET", path)
            self.assertEqual((status, len(whole)), (200, size))
            etag = headers["etag"]

            def ranged(value):
                return request(server, "GET", path, headers={"Range": value})

            for past in (f"bytes={size}-", f"bytes={size * 10}-{size * 20}", "bytes=-0"):
                status, h, _ = ranged(past)
                self.assertEqual(status, 416, past)
                self.assertEqual(h.get("content-range"), f"bytes */{size}", past)
                bad += 1
            status, h, b = ranged(f"bytes=0-{size * 10}")
            self.assertEqual((status, b), (206, whole))
            self.assertEqual(h["content-range"], f"bytes 0-{size - 1}/{size}")
            status, _, b = ranged("bytes=2-9")
            self.assertEqual((status, b), (206, whole[2:10]))
            status, _, b = ranged("bytes=-5")
            self.assertEqual((status, b), (206, whole[-5:]))
            status, _, b = ranged("bytes=0-1,4-6")  # several ranges: the whole file
            self.assertEqual((status, b), (200, whole))
            bad += 4

            for inm in (etag, "W/" + etag, f'"nope", {etag}', "*"):
                status, _, _ = request(server, "GET", path, headers={"If-None-Match": inm})
                self.assertEqual(status, 304, inm)
            status, _, _ = request(server, "GET", path, headers={"If-None-Match": '"nope"'})
            self.assertEqual(status, 200)
            # Changed on disk, same size: a new ETag.
            on_disk = server.tmp / "results" / job / "attempt-1" / name
            on_disk.write_bytes(whole[::-1])
            status, h, _ = request(server, "GET", path, headers={"If-None-Match": etag})
            self.assertEqual(status, 200)
            self.assertNotEqual(h["etag"], etag)
            bad += 6

            # OPTIONS and methods nobody serves.
            status, h, _ = request(server, "OPTIONS", "/jobs")
            self.assertEqual(status, 204)
            self.assertEqual(h["allow"], "GET, HEAD, POST, OPTIONS")
            self.assertEqual(request(server, "OPTIONS", "/nothing")[0], 404)
            for method in ("FOO", "TRACE", "CONNECT"):
                answer = raw(server, f"{method} /health HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n".encode())
                self.assertEqual(status_of(answer), 501, (method, answer[:200]))
            bad += 5

            # A client that half-closes after sending gets its answer.
            body = json.dumps(BAR_SPEC).encode()
            answer = raw(server, b"POST /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                         b"Content-Length: %d\r\n\r\n" % len(body) + body, half_close=True)
            self.assertEqual(status_of(answer), 201, answer[:300])
            bad += 1

            # Event streams of clients that never read are ended after
            # --event-stream-max-seconds (2 s), freeing their slots.
            status, _, b = request(server, "POST", "/jobs", json.dumps(long_spec()).encode(),
                                   {"Content-Type": "application/json"})
            self.assertEqual(status, 201, b)
            long_job = json.loads(b)["jobID"]
            idle = []
            for _ in range(2):
                s = connect(server)
                s.sendall(f"GET /jobs/{long_job}/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n".encode())
                # The first bytes of the answer only: the stream has begun
                # (its slot is taken) before the probe below, which would
                # otherwise race it and, answered 200, read a stream of its
                # own until the idle ones had aged out. Never read further.
                self.assertEqual(s.recv(12), b"HTTP/1.1 200")
                idle.append(s)
            self.assertTrue(wait_until(
                lambda: request(server, "GET", f"/jobs/{long_job}/events")[0] == 503, 5))
            start = time.monotonic()
            # 2 s of stream life plus up to 250 ms of polling; 8 s is generous.
            freed = wait_until(lambda: self._stream_opens(server, long_job), 8, 0.2)
            waited = time.monotonic() - start
            for s in idle:
                s.close()
            self.assertTrue(freed, "idle streams kept their slots")
            request(server, "POST", f"/jobs/{long_job}/cancel")
            bad += 2
        record(item=9, bad_inputs=bad, idle_stream_slots_freed_after_s=round(waited, 2))

    @staticmethod
    def _stream_opens(server, job) -> bool:
        with connect(server, 3.0) as s:
            s.sendall(f"GET /jobs/{job}/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n".encode())
            return status_of(s.recv(4096)) == 200

    def test_stream_cap_above_http_threads_is_refused(self):
        with tempfile.TemporaryDirectory() as tmp:
            r = subprocess.run([str(server_binary()), "--port", "0", "--db", f"{tmp}/db.sqlite",
                                "--http-threads", "8", "--max-event-streams", "8"],
                               capture_output=True, text=True, timeout=20, stdin=subprocess.DEVNULL)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("--max-event-streams", r.stderr)
        record(item=9, bad_inputs=1)


class InsecureStartTest(unittest.TestCase):
    """Item 10: a non-loopback host without a token, an empty --token, and a
    secret on the command line."""

    def run_server(self, args, env_token=None):
        env = dict(os.environ)
        env.pop("HMPM_TOKEN", None)
        if env_token is not None:
            env["HMPM_TOKEN"] = env_token
        with tempfile.TemporaryDirectory() as tmp:
            return subprocess.run([str(server_binary()), "--port", "0", "--db", f"{tmp}/db.sqlite"]
                                  + args, capture_output=True, text=True, timeout=20, env=env,
                                  stdin=subprocess.DEVNULL)

    def test_insecure_starts_are_refused(self):
        for host in ("0.0.0.0", "::"):
            r = self.run_server(["--host", host])
            self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
            self.assertIn("token", r.stderr)
            self.assertNotIn("listening", r.stdout)
        r = self.run_server(["--token", ""], env_token="from-env")
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("--token", r.stderr)
        r = self.run_server(["--host", "0.0.0.0", "--token-file", "/nonexistent/token"])
        self.assertEqual(r.returncode, 2, r.stderr)

        # --token-file: the secret works and is not in the process list.
        with tempfile.TemporaryDirectory() as tmp:
            token_file = Path(tmp) / "token"
            token_file.write_text(TOKEN + "\n")
            with ServerProcess(workers=1, extra=["--token-file", str(token_file)]) as server:
                cmdline = Path(f"/proc/{server.proc.pid}/cmdline").read_bytes()
                self.assertNotIn(TOKEN.encode(), cmdline)
                self.assertEqual(request(server, "GET", "/jobs")[0], 401)
                status, _, _ = request(server, "GET", "/jobs",
                                       headers={"Authorization": f"Bearer {TOKEN}"})
                self.assertEqual(status, 200)
        record(item=10, bad_inputs=5)


if __name__ == "__main__":
    unittest.main()
