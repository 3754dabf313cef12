"""OGC API – Processes with OWSLib (Debian's python3-owslib) against a live
hmpm-server (see support.py), behind a token as a deployed server would be.

OWSLib 0.27's `owslib.ogcapi.processes.Processes` reads the landing page,
`conformance()`, `processes()` and `process(id)`; it has no execute, job
status or results call, so the execution is posted as an OGC execute
request with urllib and followed on the /jobs routes its Location names.
"""

from __future__ import annotations

import json
import time
import unittest
import urllib.error
import urllib.request

from .support import JOB_TIMEOUT_S, LiveServerCase, bar_spec, invalid_spec

try:
    import owslib
    from owslib.ogcapi.processes import Processes
except ImportError:  # pragma: no cover - depends on the machine
    owslib = None

TOKEN = "ogc-token"
CORE = "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/"


@unittest.skipIf(owslib is None, "OWSLib is not installed: apt-get install -y python3-owslib "
                                 "(or bash scripts/install-deps.sh), then run with /usr/bin/python3")
class OwsLibTest(LiveServerCase):
    server_token = TOKEN

    def setUp(self):
        super().setUp()
        self.api = Processes(self.server.url, headers={"Authorization": f"Bearer {TOKEN}"})

    def request(self, path, body=None, headers=None):
        """(status, headers, parsed JSON body) of one request to the server."""
        data = None if body is None else json.dumps(body).encode()
        req = urllib.request.Request(self.server.url + path, data=data, method="POST" if data else "GET",
                                     headers={"Authorization": f"Bearer {TOKEN}",
                                              "Content-Type": "application/json", **(headers or {})})
        try:
            with urllib.request.urlopen(req, timeout=30) as res:
                return res.status, res.headers, res.read()
        except urllib.error.HTTPError as e:
            return e.code, e.headers, e.read()

    def test_landing_page_links(self):
        rels = {link["rel"] for link in self.api.links}
        for rel in ("conformance", "processes", "job-list"):
            self.assertIn(f"http://www.opengis.net/def/rel/ogc/1.0/{rel}", rels)

    def test_conformance(self):
        classes = self.api.conformance()["conformsTo"]
        for c in ("core", "json", "job-list", "dismiss"):
            self.assertIn(CORE + c, classes)

    def test_processes_and_description(self):
        processes = self.api.processes()["processes"]
        self.assertEqual([p["id"] for p in processes], ["hmpm"])
        self.assertEqual(processes[0]["jobControlOptions"], ["async-execute"])
        process = self.api.process("hmpm")
        self.assertEqual(list(process["inputs"]), ["spec"])
        schema = process["inputs"]["spec"]["schema"]
        self.assertEqual(schema["type"], "object")
        self.assertIn("materials", schema["properties"])
        with self.assertRaises(RuntimeError):  # OWSLib raises on any non-200
            self.api.process("nope")

    def test_execute_runs_to_successful_with_results(self):
        process = self.api.process("hmpm")
        execute = next(link["href"] for link in process["links"]
                       if link["rel"] == "http://www.opengis.net/def/rel/ogc/1.0/execute")
        status, headers, body = self.request(execute, {"inputs": {"spec": bar_spec()}},
                                             {"Prefer": "respond-async"})
        self.assertEqual(status, 201, body)
        created = json.loads(body)
        self.assertEqual(headers["Location"], "/jobs/" + created["jobID"])
        self.assertEqual(headers["Preference-Applied"], "respond-async")
        self.assertEqual((created["type"], created["processID"]), ("process", "hmpm"))

        deadline = time.monotonic() + JOB_TIMEOUT_S
        doc = created
        while doc["status"] in ("accepted", "running") and time.monotonic() < deadline:
            time.sleep(0.1)
            doc = json.loads(self.request(headers["Location"])[2])
        self.assertEqual(doc["status"], "successful", f"{doc}\n{self.server.log_tail()}")

        status, _, body = self.request(headers["Location"] + "/results")
        self.assertEqual(status, 200, body)
        files = {f["name"]: f for f in json.loads(body)["files"]}
        status, _, series = self.request(files["series.json"]["href"])
        self.assertEqual(status, 200)
        self.assertEqual(len(series), files["series.json"]["size"])
        self.assertIn("time", json.loads(series))

        jobs = json.loads(self.request("/jobs")[2])["jobs"]
        self.assertIn(created["jobID"], [j["jobID"] for j in jobs])

    def test_invalid_spec_errors_point_into_the_spec(self):
        status, _, body = self.request("/processes/hmpm/execution", {"inputs": {"spec": invalid_spec()}})
        self.assertEqual(status, 400, body)
        problem = json.loads(body)
        self.assertEqual(problem["type"], "invalid-spec")
        paths = [e["path"] for e in problem["errors"]]
        self.assertIn("/materials/bar/youngs_modulus", paths)


if __name__ == "__main__":
    unittest.main()
